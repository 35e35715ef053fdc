"""Invariant: a sphere dragged at constant velocity across the grid feels a force that does not
depend on where its centre sits in a cell (translation invariance of Stokes flow in a box that is
periodic along the motion). The solid fraction varies continuously with the position and the
relaxed constraint of doc/METHOD.md §3.3 keeps the effective sphere position-independent, so the
drag's ripple as the centre crosses cells must stay small: issue 9 asks for at most 2 % of the
mean peak to peak. Set-up: prescribed U = 2 along x in a 6.4a cube, walls at rest in y (they
take the momentum, so the flow reaches a steady state), a/Delta = 5, Re = 0.01, dt = 1e-3: the
centre crosses one cell every 100 steps. After 200 steps of start-up the drag is steady to 1e-4
(measured); steps 201-400 cover two cells. Also asserted: the force is along -x (symmetry: the
sphere sits at mid-height, so the walls push no lift; |F_y|, |F_z| < 1e-6 |F_x|) and the torque
is zero to the same level.
Second run, the same sphere at dt = 1e-2 (0.1 cells per step, 100 steps): the scheme's steady
state does not depend on dt (doc/METHOD.md §3.3), so only the lag of the incremental lambda behind
the moving body can change the drag. Lambda is carried with the sphere (fictitious_domain_follow); measured:
mean drag over the last 50 steps -3.5 % from the dt = 1e-3 value, ripple 0.84 %. Without carrying
(-fd_carry_lambda 0): -8.0 % and 4.3 %. Asserted: within 5 % and ripple <= 2 % (issue 9's bound),
so the uncarried scheme fails both.
Third run, the absolute drag against an outside reference (issue 29; the runs above compare the
code with itself): a sphere dragged through a triply periodic cube is the simple cubic array, whose
drag coefficient K = F/(6 pi eta a U_rel) is known (Sangani & Acrivos 1982 series, = Zick & Homsy
1982 to 0.03 % here; tests/physics/sphere_array_reference.py, shared with test_fd_sphere_array).
Set-up: L = 4a (phi = 0.0654, a row of test_fd_sphere_array), a/Delta = 5, prescribed U = 2 along
x, dt = 1e-3, 300 steps, a uniform body force f_b = -6 pi K_ref U/L^3 on the fluid. The reference
applies exactly when
 (1) U_rel = U - <u>, <u> the box-mean velocity of fluid and sphere together (the array's frame).
     A prescribed sphere does not fix <u>: the box's momentum obeys rho V d<u>/dt = f_b V - F_x,
     so <u> settles (time constant rho V/(6 pi K) = 12 steps) where the drag balances f_b V; f_b
     only sets the drag's size, not K (0.7 f_b: the same K to 1e-5, measured). <u> at every step
     is the momentum budget summed over the series, rho V <u>^n = sum_k dt (f_b V - F_x^k) (a
     periodic box's pressure and viscous stresses add no momentum), checked against the mean of u
     in the final fields file to 1e-6 U (measured 5e-15);
 (2) the state is steady and averaged over positions along the motion: K is the mean over steps
     101-200 and 201-300, one cell crossed each (ripple 4e-4 within a window); the two windows
     agree to 1e-3 (measured 4e-5).
Measured: K = 2.8354 against K_ref = 2.8419, -0.23 %. Asserted: |K/K_ref - 1| <= 0.5 %. Reason:
the discrete sphere's own error at this a/Delta and phi is what test_fd_sphere_array measures,
-0.18 % for the free sphere at the same position (0.37 L; +0.26 % at a/Delta = 10); it depends on
where the centre sits in the cell across the motion (free sphere, y = z from a cell corner to a
cell centre: -0.31 % to -0.15 %; dragged sphere: -0.38 % to -0.19 %). Dragging adds -0.04 to
-0.07 % at dt = 1e-3, mostly the lag of lambda behind the moving body (it shrinks with dt: -0.50,
-0.23, -0.18 % at dt = 2e-3, 1e-3, 5e-4). 0.5 % bounds all of these with a margin of 0.1 % at the worst
position and twice the error at this one; it fails when the dragged sphere departs from the free
one by more than ~0.3 %, far inside what a broken radius correction does (radius_offset = 0:
-17.7 %; slip_kappa = 0: +28 %) and six times tighter than issue 9's 3 % for the array."""
import glob
import math
import os
import numpy as np
import fdsusp_testlib as T
from sphere_array_reference import k_reference  # noqa: E402

DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 0 /
&fluid reynolds = 0.01 /
&time dt = {dt}, steps = {steps} /
&output directory = 'out', progress_every = 100 /
&particles number = 1, motion = 'prescribed', position(:,1) = 3.2, 3.2, 3.2, velocity(:,1) = 2, 0, 0 /
"""
d = T.scratch('fd_moving_sphere')
T.run(T.write_deck(d, 'm.nml', DECK.format(dt=1e-3, steps=400)), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
f = s['particles/force_hydro'][:, 0, :]
t = s['particles/torque_hydro'][:, 0, :]
x = s['particles/position'][:, 0, 0]
fx = f[200:400, 0]
ripple = (fx.max() - fx.min()) / abs(fx.mean())
T.check(x[399] - x[200] > 0.39, 'the centre crossed %.2f cells in steps 201-400' % ((x[399] - x[200]) / 0.2))
T.check(ripple <= 0.02, 'drag %.4f, ripple peak to peak %.2e of the mean <= 2e-2' % (fx.mean(), ripple))
side = np.abs(f[200:400, 1:]).max() / abs(fx.mean())
T.check(side < 1e-6, 'no lift or side force: max(|F_y|,|F_z|)/|F_x| = %.1e < 1e-6' % side)
tq = np.abs(t[200:400]).max() / abs(fx.mean())
T.check(tq < 1e-6, 'no torque: max|T|/|F_x| = %.1e < 1e-6' % tq)

d = T.scratch('fd_moving_sphere_big_step')
T.run(T.write_deck(d, 'm.nml', DECK.format(dt=1e-2, steps=100)), d, np_ranks=T.RANKS)
f_big = T.series(os.path.join(d, 'out'))['particles/force_hydro'][50:100, 0, 0]
change = f_big.mean() / fx.mean() - 1
ripple = (f_big.max() - f_big.min()) / abs(f_big.mean())
T.check(abs(change) <= 0.05, '0.1 cells per step: mean drag %.4f, %+.2f %% from dt = 1e-3 (<= 5 %%)'
        % (f_big.mean(), 100 * change))
T.check(ripple <= 0.02, '0.1 cells per step: ripple peak to peak %.2e of the mean <= 2e-2' % ripple)

# the absolute drag: the dragged sphere as a simple cubic array (triply periodic cube)
ARRAY = """&domain box = {L}, {L}, {L}, cells_per_radius = 5, y_boundary = 'periodic', shear_rate = 0 /
&fluid reynolds = {re}, body_force = {fb:.15e}, 0, 0 /
&time dt = {dt}, steps = {steps} /
&output directory = 'out', progress_every = 100 /
&particles number = 1, motion = 'prescribed', position(:,1) = {c}, {c}, {c}, velocity(:,1) = {U}, 0, 0 /
"""
L, U, re, dt, steps, cell = 4.0, 2.0, 0.01, 1e-3, 300, 100   # cell: steps per cell crossed (U dt = Delta/100)
V = L ** 3
phi = 4 * math.pi / 3 / V
kref = k_reference(phi)
fb = -6 * math.pi * kref * U / V
d = T.scratch('fd_moving_sphere_array')
T.run(T.write_deck(d, 'a.nml', ARRAY.format(L=L, re=re, fb=fb, dt=dt, steps=steps, c=0.37 * L, U=U)), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
fx = s['particles/force_hydro'][:, 0, 0]
u_mean = np.cumsum(dt * (fb * V - fx)) / (re * V)          # the box's momentum budget, rho = Re
u_field = T.read_h5(sorted(glob.glob(os.path.join(d, 'out', 'fields_*.h5')))[-1], ['u'])['u'].mean()
T.check(abs(u_mean[-1] - u_field) <= 1e-6 * U, 'box-mean velocity: momentum budget %.6e, final field %.6e '
        '(|difference| <= 1e-6 U)' % (u_mean[-1], u_field))
k = -fx / (6 * math.pi * (U - u_mean))
k1, k2 = k[steps - 2 * cell:steps - cell].mean(), k[steps - cell:].mean()
T.check(abs(k2 / k1 - 1) <= 1e-3, 'steady: K over steps %d-%d %.5f and %d-%d %.5f agree to %.1e <= 1e-3'
        % (steps - 2 * cell + 1, steps - cell, k1, steps - cell + 1, steps, k2, abs(k2 / k1 - 1)))
kk = 0.5 * (k1 + k2)
T.check(abs(kk / kref - 1) <= 5e-3, 'L = %.1f, phi = %.4f, U - <u> = %.5f: K = %.4f, reference %.4f, error %+.2f %% '
        '(<= 0.5 %%; the free sphere: -0.18 %%)' % (L, phi, U - u_mean[-1], kk, kref, 100 * (kk / kref - 1)))
T.finish()
