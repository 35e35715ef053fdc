"""Invariant: the discrete steady Stokes solution converges to the exact (manufactured) solution
at second order on the MAC grid, in a triply periodic box and between two no-slip walls
(the walls also shear the flow: a Couette part that needs no forcing is added to the exact
solution).  Grids 16^3, 32^3, 64^3 (a/Delta = 5, 10, 20 in a 3.2a cube).
Asserted: observed order >= 1.8 between each pair of grids for the max-norm velocity error and
for the max-norm pressure error (the MAC scheme is formally second order: 2 minus a margin for
the pre-asymptotic range), and the projected velocity is divergence-free to 1e-10 relative
(max|div u| Delta / max|u|) at every step, which the pressure solve's tolerance guarantees.
The runs use backward Euler (viscous_theta = 1): its steady state is the same discrete Stokes
solution as Crank-Nicolson's, reached in ~30 steps instead of hundreds.
Prints the table recorded in doc/VALIDATION.md."""
import math
import os
import fdsusp_testlib as T

DECK = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = {cpr}, y_boundary = '{yb}', shear_rate = {shear} /
&fluid reynolds = 0.01, viscous_theta = 1.0, velocity_tolerance = 1e-10, pressure_tolerance = 1e-10 /
&time dt = 0.05, steps = 400, steady_tolerance = 1e-9 /
&output directory = 'out', progress_every = 1000 /
&verification manufactured_solution = .true. /
"""

# the six runs are independent (a directory each): run together, at most 2 ranks at a time, the
# parallel ones (a/Delta = 20) first
BOXES = (('periodic', 0), ('walls', 1))
where, runs = {}, []
for cpr in (20, 10, 5):
    for yb, shear in BOXES:
        d = where[yb, cpr] = T.scratch('mms_%s_%d' % (yb, cpr))
        runs.append(dict(deck=T.write_deck(d, 'mms.nml', DECK.format(cpr=cpr, yb=yb, shear=shear)), cwd=d,
                         np_ranks=T.RANKS if cpr == 20 else 1))
logs = {run['cwd']: out for run, (_, out, _) in zip(runs, T.run_many(runs))}

for yb, shear in BOXES:
    errors = []
    for cpr in (5, 10, 20):
        d = where[yb, cpr]
        out = logs[d]
        T.check('steady state at step' in out, '%s a/Delta=%d reached its steady state' % (yb, cpr))
        s = T.series(os.path.join(d, 'out'))
        e = (s['mms_error_velocity_max'][-1], s['mms_error_pressure_max'][-1], s['mms_error_pressure_rms'][-1])
        errors.append(e)
        T.check(s['divergence'].max() <= 1e-10,
                '%s a/Delta=%d: max relative divergence over %d steps %.2e <= 1e-10'
                % (yb, cpr, len(s['divergence']), s['divergence'].max()))
    print('\n%s box: cells  |u-u_e|max  order  |p-p_e|max  order  |p-p_e|rms  order' % yb)
    for i, (cells, e) in enumerate(zip((16, 32, 64), errors)):
        if i == 0:
            print('  %3d^3   %.3e    -     %.3e    -     %.3e    -' % (cells, *e))
        else:
            o = [math.log2(errors[i - 1][k] / e[k]) for k in range(3)]
            print('  %3d^3   %.3e  %.2f   %.3e  %.2f   %.3e  %.2f' % (cells, e[0], o[0], e[1], o[1], e[2], o[2]))
            T.check(o[0] >= 1.8, '%s: velocity order %.2f >= 1.8 (%d^3 to %d^3)' % (yb, o[0], cells // 2, cells))
            T.check(o[1] >= 1.8, '%s: pressure order %.2f >= 1.8 (%d^3 to %d^3)' % (yb, o[1], cells // 2, cells))
T.finish()
