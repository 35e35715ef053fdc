"""Invariant: a sphere dragged at constant velocity across the grid feels a force that does not
depend on where its centre sits in a cell (translation invariance of Stokes flow in a box that is
periodic along the motion). The solid fraction varies continuously with the position and the
relaxed constraint of method.md §1.5b keeps the effective sphere position-independent, so the
drag's ripple as the centre crosses cells must stay small: issue 9 asks for at most 2 % of the
mean peak to peak. Set-up: prescribed U = 2 along x in a 6.4a cube, walls at rest in y (they
take the momentum, so the flow reaches a steady state), a/Delta = 5, Re = 0.01, dt = 1e-3: the
centre crosses one cell every 100 steps. After 200 steps of start-up the drag is steady to 1e-4
(measured); steps 201-400 cover two cells. Also asserted: the force is along -x (symmetry: the
sphere sits at mid-height, so the walls push no lift; |F_y|, |F_z| < 1e-6 |F_x|) and the torque
is zero to the same level.
Second run, the same sphere at dt = 1e-2 (0.1 cells per step, 100 steps): the scheme's steady
state does not depend on dt (method.md §1.5b), so only the lag of the incremental lambda behind
the moving body can change the drag. Lambda is carried with the sphere (fictitious_domain_follow); measured:
mean drag over the last 50 steps -3.5 % from the dt = 1e-3 value, ripple 0.84 %. Without carrying
(-fd_carry_lambda 0): -8.0 % and 4.3 %. Asserted: within 5 % and ripple <= 2 % (issue 9's bound),
so the uncarried scheme fails both."""
import os
import sys
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..'))
import fdsusp_testlib as T

DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 0 /
&fluid reynolds = 0.01 /
&time dt = {dt}, steps = {steps} /
&output directory = 'out', progress_every = 100 /
&particles number = 1, motion = 'prescribed', position(:,1) = 3.2, 3.2, 3.2, velocity(:,1) = 2, 0, 0 /
"""
d = T.scratch('fd_moving_sphere')
T.run(T.write_deck(d, 'm.nml', DECK.format(dt=1e-3, steps=400)), d, np_ranks=2)
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
T.run(T.write_deck(d, 'm.nml', DECK.format(dt=1e-2, steps=100)), d, np_ranks=2)
f_big = T.series(os.path.join(d, 'out'))['particles/force_hydro'][50:100, 0, 0]
change = f_big.mean() / fx.mean() - 1
ripple = (f_big.max() - f_big.min()) / abs(f_big.mean())
T.check(abs(change) <= 0.05, '0.1 cells per step: mean drag %.4f, %+.2f %% from dt = 1e-3 (<= 5 %%)'
        % (f_big.mean(), 100 * change))
T.check(ripple <= 0.02, '0.1 cells per step: ripple peak to peak %.2e of the mean <= 2e-2' % ripple)
T.finish()
