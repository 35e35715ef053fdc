"""Invariant: the initial guess of the viscous solves changes the solution only at the solver
tolerance, and the direct (FFT) solves of the default path give the solution the Krylov solves
converge to. The Helmholtz solves start from the extrapolation 2 u*^n - u*^{n-1} of the last two
provisional velocities (mod_fluid); `-fluid_extrapolate 0` starts them from u^n as before. Both
solve the same systems to the same relative tolerance, so two free spheres closing in shear
(lubrication and Lambda at work, the scene of the pair test) must move the same way in both runs.

Tolerances (observed in brackets, 2026-11-25):
  - particle velocities to 1e-4 of the flow's velocity scale U = gamma_dot L_y / 2 = 4 (1e-6),
    stresslets to 1e-4 of their size (1.6e-5), positions to 1e-5 a (7e-8), after 150 steps: the
    solves stop at a residual of 1e-6 |b|, |b| ~ (Re/dt) U, and with the Jacobi-CG condition
    number 1 + 12 theta eta dt/(Re h^2) = 15.4 here a solution is fixed to ~2e-5 U per step;
    the particle step and the positions carry such differences without amplifying them over a
    0.225 strain;
  - the direct solves (-fluid_solver fft, the default; exact to round-off) against both Krylov
    runs (-fluid_solver krylov, tolerance 1e-6): the same bounds, since each Krylov run is within
    them of the exact solution;
  - the extrapolated guess needs at least 25 % fewer viscous iterations per step (21 against 41;
    the reason it exists: 39 -> 18 in the 10a pair test, doc/BENCHMARKS.md §10); iteration counts
    are deterministic, not a timing.
"""
import os
import re

import numpy as np

import fdsusp_testlib as T  # noqa: E402

DECK = """&domain box = 8.0, 8.0, 8.0, cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1.5e-3, steps = 150 /
&output directory = 'out', progress_every = 50, series_every = 10 /
&particles number = 2,
  position(:,1) = 2.9, 3.8, 4.0,
  position(:,2) = 5.1, 4.2, 4.0 /
&lubrication model = 'full' /
"""


# the three runs are independent (a directory each): run together, two at a time
NAMES = {'extrapolated': ['-fluid_solver', 'krylov'], 'plain': ['-fluid_solver', 'krylov', '-fluid_extrapolate', '0'],
         'direct': []}
where = {name: T.scratch('fluid_guess_' + name) for name in NAMES}
logs = dict(zip(NAMES, (out for _, out, _ in T.run_many([dict(deck=T.write_deck(where[name], 'd.nml', DECK),
                                                                cwd=where[name], args=args)
                                                           for name, args in NAMES.items()]))))


def run(name):
    its = [float(x) for x in re.search(r'mean iterations u v w p:\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)', logs[name]).groups()]
    return T.series(os.path.join(where[name], 'out')), its


extrapolated, its_x = run('extrapolated')
plain, its_p = run('plain')
direct, _ = run('direct')
U = 4.0                             # gamma_dot L_y / 2: the wall speed in the frame of the box centre
for first, second, what in ((extrapolated, plain, 'extrapolated vs plain guess'),
                            (direct, extrapolated, 'direct vs Krylov (extrapolated)'),
                            (direct, plain, 'direct vs Krylov (plain)')):
    for q, scale, tol in (('particles/velocity', U, 1e-4), ('particles/stresslet_hydro', None, 1e-4),
                          ('particles/position', 1.0, 1e-5)):
        a, b = first[q][-1], second[q][-1]
        scale = scale or np.abs(b).max()
        diff = np.abs(a - b).max() / scale
        T.check(diff <= tol, '%s after 150 steps: %s differ by %.1e of %.3g (<= %g)' % (q, what, diff, scale, tol))
viscous_x, viscous_p = sum(its_x[:3]), sum(its_p[:3])
T.check(viscous_x <= 0.75 * viscous_p, 'viscous CG iterations per step: %.1f extrapolated vs %.1f plain (u/v/w %s vs %s)'
        % (viscous_x, viscous_p, its_x[:3], its_p[:3]))
T.finish()
