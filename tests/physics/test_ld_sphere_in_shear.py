"""Invariant: in the lubrication dynamics mode (&fluid model = 'none') one free sphere in simple
shear, beyond every pair and wall cut-off, feels only the one-body Stokes resistance relative to
the imposed flow, so it translates with the local fluid, U = gamma_dot (y - Ly/2) e_x, rotates at
Omega_z = -gamma_dot/2 and carries the stresslet S_xy = (10/3) pi eta a^3 gamma_dot (Einstein),
exactly: the 6N system is one 6x6 diagonal block solved directly, so the only error is round-off
(tolerance 1e-13 relative, some 500 machine epsilons; measured 0). Checked between walls (the
sphere 9a from each, beyond the default 1a wall cut-off) and with Lees-Edwards boundaries, where
an external force 6 pi eta a x 0.1 e_y drives it across y = Ly (U_y = 0.1, to round-off): it
continues from the image below with the velocity of its new height, U_x = gamma_dot (y - Ly/2)
through the crossing, and its rotation and stresslet do not change."""
import math
import os
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 10, 20, 10, y_boundary = '{boundary}', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 0.01, steps = 50 /
&output directory = 'out', progress_every = 50 /
&particles number = 1, position(:,1) = 5.0, {y}, 5.0, external_force(:,1) = 0, {fy}, 0 /
"""
S_EXACT = 10 / 3 * math.pi
TOL = 1e-13
for boundary, y, uy in (('walls', 10.0, 0.0), ('lees-edwards', 19.97, 0.1)):
    d = T.scratch('ld_sphere_shear_' + boundary)
    T.run(T.write_deck(d, 's.nml', DECK.format(boundary=boundary, y=y, fy=repr(6 * math.pi * uy))), d)
    s = T.series(os.path.join(d, 'out'))
    om = s['particles/omega'][:, 0, :]
    st = s['particles/stresslet_hydro'][:, 0, :, :]
    u = s['particles/velocity'][:, 0, :]
    # the position after the step; the velocity was that of the position before it
    x = np.vstack([[5.0, y, 5.0], s['particles/position'][:-1, 0, :]])
    e_om = np.abs(om - [0, 0, -0.5]).max() / 0.5
    T.check(e_om <= TOL, '%s: Omega = (0, 0, -1/2) at every step, max error %.1e (<= %.0e)' % (boundary, e_om, TOL))
    e_s = np.abs(st[:, 0, 1] - S_EXACT).max() / S_EXACT
    T.check(e_s <= TOL and np.abs(st[:, 0, 1] - st[:, 1, 0]).max() == 0,
            '%s: S_xy = (10/3) pi = %.12f at every step, max error %.1e (<= %.0e), symmetric'
            % (boundary, S_EXACT, e_s, TOL))
    others = np.abs(st.reshape(len(st), 9)[:, [0, 2, 4, 5, 6, 7, 8]]).max()
    T.check(others <= TOL * S_EXACT, '%s: every other stresslet component zero (max %.1e)' % (boundary, others))
    # the record of the step that wraps the sphere holds its velocity in the frame of the wrapped
    # (recorded) position: the step's U_x minus gamma_dot Ly
    jump = np.round((u[:, 0] - (x[:, 1] - 10.0)) / 20.0)
    e_u = np.abs(u[:, 0] - (x[:, 1] - 10.0) - 20.0 * jump).max()
    T.check(np.array_equal(np.nonzero(jump)[0], np.nonzero(np.diff(s['particles/position'][:, 0, 1], prepend=y) < -10)[0]),
            '%s: the velocity changes frame (by -gamma_dot Ly) exactly at the wrapping step(s) (%d)'
            % (boundary, np.count_nonzero(jump)))
    e_uy = np.abs(u[:, 1] - uy).max() + np.abs(u[:, 2]).max()
    T.check(e_u <= TOL * 10 and e_uy <= TOL,
            '%s: U = gamma_dot (y - Ly/2) e_x + (0, %g, 0), max errors %.1e, %.1e a gamma_dot (<= %.0e)'
            % (boundary, uy, e_u, e_uy, TOL * 10))
    if boundary == 'lees-edwards':
        crossed = (x[:, 1] < 1.0).any()
        T.check(crossed, 'lees-edwards: the sphere crossed y = Ly and re-entered from below (y %.3f -> %.3f)'
                % (x[0, 1], x[-1, 1]))
T.finish()
