"""Invariant: stress control (doc/INPUT.md "&shear" control = 'stress'; doc/METHOD.md §7.4; issue
46) sets the rate that gives the asked mean shear stress, and gives back the rate of a
rate-controlled run at the stress that run measured.
A. Lubrication dynamics, 49 rough frictional spheres (phi 0.4, eps_r 5e-3, mu_d 0.5, Lees-Edwards,
   8a box), dt 5e-3, 3000 steps (strain ~15), statistics after strain 1 in 7 blocks of strain 2:
   1. a rate-controlled run (rate 1) measures the mean shear stress S = <gamma_dot + Sigma^h_xy +
      Sigma^c_xy> over the window (block mean and its standard error);
   2. the stress-controlled run at S: at every record the stress its step solved for is S (the
      column shear/stress, to 1e-12 relative: the step is affine in the rate, so the one scalar
      equation is solved exactly), and so is the stress the statistics sampled from the same
      stresslets by their own sum (rate + core/stress_hydro_xy + core/stress_contact_xy, to 1e-12);
   3. the strain advances with the spheres' Adams-Bashforth step, dt (3/2 gamma_dot^n -
      1/2 gamma_dot^{n-1}) (forward Euler on the first step), and the Lees-Edwards offset is that
      strain times Ly modulo Lx (to 1e-12 a);
   4. fdsusp.protocols.stress_control_rate takes the mean rate over the summary's blocks as the
      test does (to 1e-12), and the viscosity S/<rate>;
      scripts/rheology.py redoes its summary from series.h5 (stresses over gamma_dot_ref, as for
      any rate that varies) and agrees with summary.json;
   5. the mean rate over the same window gives back the imposed rate 1 within 3 combined standard
      errors: its own block error, and the error of S carried into the rate, err(S)/S (the
      stress grows nearly in proportion to the rate: eta_r changes little over the few percent
      that S is uncertain). Measured: S = 10.18 +- 0.41, mean rate 1.029 +- 0.047 (0.16 of the
      tolerance 0.19; the rate itself ranges over 0.39 .. 2.39 from step to step).
C. Lubrication dynamics between walls (phi 0.35, 150 steps), stress 5: the stress is 5 at every
   record (the walls' terms, wall lubrication and wall contacts, are affine in the rate too, to
   1e-12), and the run on 2 ranks is the run on 1 to 1e-10 of each column's largest magnitude (the
   6N system is solved in parallel, doc/DESIGN.md "Parallelism": CG's inner products sum in
   another order, and the two solves of a step agree to the solver's tolerance 1e-12; measured
   2026-11-28 at most 7.4e-13 of the largest, the contact stresslets; a share lost or doubled in
   the parallel solve, or in the gather of the links, changes them at O(1)).
B. DNS, the fluid alone between walls (4a cube, a/Delta = 2, Re 0.01, backward Euler, dt 0.01,
   from rest), stress 2.5: the mean wall stress is 2.5 at every record (to 1e-12: the step plus a
   multiple of its unit wall-speed response), both walls alike (the flow is antisymmetric), and
   once the viscous transient has died (Re Ly^2 = 0.16: 300 steps are 19 relaxation times of the
   slowest mode) the rate is the exact Couette rate S/eta = 2.5, to 1e-12.
About a minute on one core; C's and B's one-rank runs go beside A's first."""
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
import numpy as np
import fdsusp_testlib as T
from fdsusp import protocols

DT, LY = 5.0e-3, 8.0
LD = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear {shear} /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = 3000 /
&output directory = '{out}', progress_every = 100000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 1.0, average_strain = 14.0, blocks = 7 /
"""
DISCARD, BLOCKS = 200, 7


def block_mean(x):
    """Mean of the block means over BLOCKS equal blocks, and its standard error (ddof 1)."""
    b = np.array([m.mean() for m in np.array_split(x, BLOCKS)])
    return b.mean(), b.std(ddof=1) / np.sqrt(BLOCKS)


# C. lubrication dynamics between walls, on 1 and 2 ranks; B. the fluid alone between walls
WALLS = LD.replace("y_boundary = 'lees-edwards'", "y_boundary = 'walls'").replace('steps = 3000', 'steps = 150') \
    .replace('solid_fraction = 0.4, seed = 1', 'solid_fraction = 0.35, seed = 4') \
    .replace('discard_strain = 1.0, average_strain = 14.0, blocks = 7', 'discard_strain = 0.0, average_strain = 0.7, blocks = 2')
FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear control = 'stress', stress = 2.5 /
&fluid reynolds = 0.01, viscous_theta = 1.0 /
&time dt = 1.0e-2, steps = 300 /
&output directory = 'fluid', progress_every = 1000 /
"""
d = T.scratch('protocol_stress')
w = {ranks: T.scratch('protocol_stress_walls_%d' % ranks) for ranks in (1, T.RANKS)}
walls = {ranks: T.write_deck(w[ranks], 'walls.nml', WALLS.format(shear="control = 'stress', stress = 5.0", out='walls'))
         for ranks in w}
# A's rate-controlled run goes on one core while the one-rank runs of C and B, independent of it and
# of one another (each in its own output directory), run on the other; C's parallel run follows A
rate_run = ThreadPoolExecutor(max_workers=1).submit(
    T.run, T.write_deck(d, 'rate.nml', LD.format(shear='rate = 1.0', out='rate')), d)
T.run(walls[1], w[1])
T.run(T.write_deck(d, 'fluid.nml', FLUID), d)
rate_run.result()
s = T.series(os.path.join(d, 'rate'))
window = s['step'] > DISCARD
sigma = s['shear/rate'] + s['core/stress_hydro'][:, 3] + s['core/stress_contact'][:, 3]
S, S_err = block_mean(sigma[window])
T.check(np.all(s['shear/rate'] == 1.0) and S_err > 0, 'rate control: the rate is 1 at every record')

T.run(T.write_deck(d, 'stress.nml', LD.format(shear="control = 'stress', stress = %.15g" % S, out='stress')), d)
s = T.series(os.path.join(d, 'stress'))
rate = s['shear/rate']
miss = np.max(np.abs(s['shear/stress'] - S)) / S
T.check(miss < 1e-12, 'the stress each step solved for is S = %.4f (largest relative miss %.1e)' % (S, miss))
sampled = rate + s['core/stress_hydro'][:, 3] + s['core/stress_contact'][:, 3]
miss = np.max(np.abs(sampled - S)) / S
T.check(miss < 1e-12, 'the statistics\' own sum over the stresslets is S at every record (%.1e)' % miss)

advance = np.r_[rate[0], 1.5 * rate[1:] - 0.5 * rate[:-1]]
strain = s['shear/strain']
miss = np.max(np.abs(np.diff(strain) - DT * advance[:-1]))
T.check(strain[0] == 0.0 and miss < 1e-12,
        'the strain advances by dt (3/2 rate_n - 1/2 rate_n-1) each step (%.1e)' % miss)
expected = ((strain + DT * advance) * LY) % LY
gap = np.abs(s['lees_edwards_offset'] - expected)
miss = np.max(np.minimum(gap, LY - gap))
T.check(miss < 1e-12, 'the Lees-Edwards offset is the strain times Ly (%.1e a)' % miss)

mean, err = block_mean(rate[s['step'] > DISCARD])
v = protocols.stress_control_rate(os.path.join(d, 'stress'))
T.check(v['blocks'] == BLOCKS and abs(v['rate'] - mean) < 1e-12 and abs(v['rate_error'] - err) < 1e-12
        and abs(v['viscosity'] - S / mean) < 1e-12 * S,
        'fdsusp.protocols.stress_control_rate: the mean rate %.4f +- %.4f over the 7 blocks, eta = S/rate %.3f'
        % (v['rate'], v['rate_error'], v['viscosity']))
tolerance = 3.0 * np.hypot(err, S_err / S)
print('S = %.4f +- %.4f; stress control at S: mean rate %.4f +- %.4f (rate range %.3f .. %.3f)'
      % (S, S_err, mean, err, rate.min(), rate.max()))
T.check(abs(mean - 1.0) <= tolerance,
        'the mean rate under stress control gives back the rate 1: %.4f, |%.4f| <= 3 sigma = %.4f'
        % (mean, mean - 1.0, tolerance))
T.check(rate.min() > 0, 'the rate stays positive under a positive stress')
p = protocols.settings(os.path.join(d, 'stress'))
T.check(p['control'] == 'stress' and abs(p['stress'] - S) < 1e-13 * S and p['protocol'] == 'steady',
        'the series attributes record stress control at S (fdsusp.protocols.settings)')
p = subprocess.run([sys.executable, os.path.join(T.ROOT, 'scripts', 'rheology.py'), os.path.join(d, 'stress'), '--compare'],
                   capture_output=True, text=True)
T.check(p.returncode == 0 and 'agrees to 1e-10' in p.stdout,
        'scripts/rheology.py reproduces summary.json of the stress-controlled run (stresses over gamma_dot_ref)')

# C. lubrication dynamics between walls, on 1 (run above) and 2 ranks
if T.RANKS != 1:
    T.run(walls[T.RANKS], w[T.RANKS], np_ranks=T.RANKS)
s = T.series(os.path.join(w[1], 'walls'))
miss = max(np.max(np.abs(s['shear/stress'] - 5.0)),
           np.max(np.abs(s['shear/rate'] + s['core/stress_hydro'][:, 3] + s['core/stress_contact'][:, 3] - 5.0))) / 5.0
T.check(miss < 1e-12 and np.any(s['contacts_wall'] > 0) and np.all(s['lubrication_walls'] > 0),
        'walls: the stress is 5 at every record, wall contacts and wall lubrication in the step (%.1e)' % miss)
T.compare_h5(os.path.join(w[1], 'walls', 'series.h5'), os.path.join(w[T.RANKS], 'walls', 'series.h5'),
             'walls: %d ranks (the links shared out, the solve in parallel) against 1' % T.RANKS, rtol=1e-10, skip=('wall_time',))

# B. the fluid alone between walls (run above)
s = T.series(os.path.join(d, 'fluid'))
tau = 0.5 * (s['tau_wall_bottom'] + s['tau_wall_top'])
miss = max(np.max(np.abs(tau - 2.5)), np.max(np.abs(s['tau_wall_bottom'] - s['tau_wall_top'])),
           np.max(np.abs(s['shear/stress'] - 2.5)))
T.check(miss < 1e-12, 'fluid: the mean wall stress is 2.5 at every record, both walls alike (%.1e)' % miss)
rate = s['shear/rate']
T.check(rate[0] < 2.5 and np.all(np.diff(rate) >= -1e-12),
        'fluid: from rest the rate rises to its steady value (%.4f at the first record)' % rate[0])
T.check(abs(rate[-1] - 2.5) < 1e-12, 'fluid: the steady rate is the Couette rate S/eta = 2.5 (%.1e)' % abs(rate[-1] - 2.5))
T.finish()
