"""Invariant: a force- and torque-free sphere in simple shear (Stokes flow) rotates at
Omega_z = -gamma_dot/2, translates with the local fluid velocity gamma_dot*(y - Ly/2) and has the
stresslet S_xy = (10/3) pi eta a^3 gamma_dot (Einstein / Batchelor & Green). Coarse set-up for
make check: a 10a x 20a x 10a Couette cell at a/Delta = 4 (40 x 80 x 40 cells), Re = 0.01,
started from the linear profile. The sphere's disturbance must diffuse across the channel, which
takes ~Re Ly^2/pi^2 = 0.4 strain, so the test steps dt = 5e-3 with backward Euler (theta = 1,
which damps the transient fastest; the steady state of the scheme does not depend on dt or
theta, doc/METHOD.md §3.3) for 200 steps = 1 strain. Measured: Omega_z then changes by 1e-4 and
S_xy by 0.2 % over the last 50 steps, both still approaching the exact values, so the remaining
transient cannot carry them out of tolerance. Finer grids and the 20a cube of issue 9 are in
doc/VALIDATION.md (bench).
Tolerances: rotation within 1 % and stresslet within 3 % (issue 9). Confinement corrections are
below them: the walls 10a away change S_xy by O((a/10a)^3) ~ 0.1 % and the periodic images 10a
apart by O(phi) = 0.4 %. For the off-centre sphere (y = Ly/2 + 3a, 7a from the top wall) the wall
slows the translation by (5/16)(a/7a)^3 = 0.1 % (Goldman, Cox & Brenner 1967), well inside the
1 % asserted. The moving sphere is run at dt = 1e-3 (Crank-Nicolson): it must move a small
fraction of a cell per relaxation time of lambda (at dt = 5e-3 it moves 0.06 Delta per step and
its rotation is noisy by 10 %, measured); its velocity settles within 50 steps. The fictitious
domain alone (&lubrication model = 'none'): the sphere stays >= 6a from the walls, beyond any
lubrication cut-off."""
import math
import os
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 10, 20, 10, cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', viscous_theta = {theta} /
&time dt = {dt}, steps = {steps} /
&output directory = 'out', progress_every = 50 /
&particles number = 1, position(:,1) = 5.0, {y}, 5.0 /
&lubrication model = 'none' /
"""
S_EXACT = 10 / 3 * math.pi

d = T.scratch('fd_sphere_shear_centre')
T.run(T.write_deck(d, 's.nml', DECK.format(y=10.0, steps=200, dt=5e-3, theta=1)), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
om = s['particles/omega'][:, 0, :]
st = s['particles/stresslet_hydro'][:, 0, :, :]
u = s['particles/velocity'][:, 0, :]
change = abs(om[-1, 2] - om[-50, 2]) / 0.5
T.check(change < 5e-4, 'near steady: Omega_z changed by %.1e (relative) < 5e-4 over the last 50 steps' % change)
change = abs(st[-1, 0, 1] - st[-50, 0, 1]) / S_EXACT
T.check(change < 5e-3, 'near steady: S_xy changed by %.1e (relative) < 5e-3 over the last 50 steps' % change)
T.check(abs(om[-1, 2] / -0.5 - 1) <= 0.01, 'centre: Omega_z = %.5f, exact -0.5, error %+.2f %% (<= 1 %%)'
        % (om[-1, 2], 100 * (om[-1, 2] / -0.5 - 1)))
sxy = 0.5 * (st[-1, 0, 1] + st[-1, 1, 0])
T.check(abs(sxy / S_EXACT - 1) <= 0.03, 'centre: S_xy = %.4f, exact (10/3) pi = %.4f, error %+.2f %% (<= 3 %%)'
        % (sxy, S_EXACT, 100 * (sxy / S_EXACT - 1)))
T.check(np.abs(u[-1]).max() < 1e-6, 'centre: the sphere stays in place (|U| = %.1e < 1e-6)' % np.abs(u[-1]).max())
T.check(abs(st[-1, 0, 1] - st[-1, 1, 0]) < 1e-10 * abs(sxy), 'the stresslet is symmetric')

d = T.scratch('fd_sphere_shear_offcentre')
T.run(T.write_deck(d, 's.nml', DECK.format(y=13.0, steps=150, dt=1e-3, theta=0.5)), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
u = s['particles/velocity'][:, 0, :]
om = s['particles/omega'][:, 0, :]
T.check(abs(u[-1, 0] / 3.0 - 1) <= 0.01, 'off-centre (y = Ly/2 + 3a): U_x = %.5f, local fluid 3.0, error %+.3f %% (<= 1 %%)'
        % (u[-1, 0], 100 * (u[-1, 0] / 3.0 - 1)))
T.check(abs(om[-1, 2] / -0.5 - 1) <= 0.01, 'off-centre: Omega_z = %.5f (within 1 %% of -0.5)' % om[-1, 2])
T.finish()
