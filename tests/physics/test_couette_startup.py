"""Invariant: plane Couette start-up. Fluid at rest between walls that start moving at -U and +U
at t = 0 (U = Ly/2, shear rate 1). Exact solution (separation of variables, nu = eta/rho = 1/Re):
  u(y,t) = U(2y/Ly - 1) + sum_{n even} 4U/(n pi) sin(n pi y/Ly) exp(-nu n^2 pi^2 t/Ly^2).
Asserted:
 - at two times (nu t/Ly^2 = 0.05 and 0.2) the computed u matches it within 1e-3 of U
   (spatial error (pi h/Ly)^2/12 ~ 1e-5, time error of Crank-Nicolson at nu dt k^2 <= 0.01
   ~ 1e-6: 1e-3 leaves room for the start-up discontinuity at the walls);
 - the steady state is the linear profile to 1e-10 of U (a linear profile is reproduced exactly
   by the second-order wall ghost, so only solver tolerance remains);
 - the shear stress on each wall equals eta 2U/Ly = 1 to 1e-8 relative;
 - v and w stay zero (no forcing drives them) to 1e-11 U: each solve stops at the round-off floor
   of mod_fluid (residual of an RMS error 100 eps U = 2.2e-14 U), which random-walks over at most
   800 steps to ~6e-13 U; any coupling defect would show at the 1e-3 level;
 - the flow is divergence-free (1e-10)."""
import math
import os
import numpy as np
import fdsusp_testlib as T

LY, RE = 20.0, 0.1
U = LY / 2
NU = 1.0 / RE
DECK = """&domain box = 1.6, {ly}, 1.6, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = {re}, viscous_theta = {theta}, velocity_tolerance = 1e-12, pressure_tolerance = 1e-12 /
&time dt = {dt}, steps = {steps}, steady_tolerance = {steady} /
&output directory = 'out', progress_every = 100 /
"""


def exact(y, t):
    u = U * (2 * y / LY - 1)
    for n in range(2, 4000, 2):
        u += 4 * U / (n * math.pi) * np.sin(n * math.pi * y / LY) * math.exp(-NU * (n * math.pi / LY) ** 2 * t)
    return u


dt = 0.01
for steps in (200, 800):
    d = T.scratch('couette_%d' % steps)
    deck = T.write_deck(d, 'c.nml', DECK.format(ly=LY, re=RE, theta=0.5, dt=dt, steps=steps, steady=0))
    T.run(deck, d)
    f = T.read_h5(os.path.join(d, 'out', 'checkpoint.h5'), ['u', 'v', 'w'])
    u = f['u']                      # (nz, ny, nx), u at y = (j + 1/2) h
    ny = u.shape[1]
    h = LY / ny
    y = (np.arange(ny) + 0.5) * h
    t = steps * dt
    err = np.abs(u - exact(y, t)[None, :, None]).max() / U
    T.check(err <= 1e-3, 't = %.1f (nu t/Ly^2 = %.3f): max|u - exact|/U = %.2e <= 1e-3' % (t, NU * t / LY ** 2, err))
    vw = max(np.abs(f['v']).max(), np.abs(f['w']).max()) / U
    T.check(vw < 1e-11, 'v and w stay zero: max(|v|,|w|)/U = %.1e < 1e-11' % vw)
    s = T.series(os.path.join(d, 'out'))
    T.check(s['divergence'].max() <= 1e-10, 'divergence at every step <= 1e-10 (max %.1e)' % s['divergence'].max())

d = T.scratch('couette_steady')
deck = T.write_deck(d, 'c.nml', DECK.format(ly=LY, re=RE, theta=1.0, dt=1.0, steps=1000, steady=1e-12))
status, out, err = T.run(deck, d)
T.check('steady state at step' in out, 'reached the steady state')
u = T.read_h5(os.path.join(d, 'out', 'checkpoint.h5'), ['u'])['u']
ny = u.shape[1]
y = (np.arange(ny) + 0.5) * (LY / ny)
lin = np.abs(u - (U * (2 * y / LY - 1))[None, :, None]).max() / U
T.check(lin <= 1e-10, 'steady profile linear: max deviation/U = %.2e <= 1e-10' % lin)
s = T.series(os.path.join(d, 'out'))
for wall in ('tau_wall_bottom', 'tau_wall_top'):
    tau = s[wall][-1]
    T.check(abs(tau - 2 * U / LY) <= 1e-8, '%s = %.12f, eta 2U/Ly = 1 to 1e-8' % (wall, tau))
T.finish()
