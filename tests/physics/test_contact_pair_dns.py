"""Invariant: contact forces enter the particle force balance of the DNS. Two free spheres in a
walled box at rest (shear_rate = 0) are pressed together along x by opposite external forces +-F
(F = 6 pi eta gamma_dot a^2, the force scale of the eps_bar rule), rough (eps_r = 0.01), frictionless.
They start touching at zero contact force (centre distance 2a + h_r). At steady state nothing
moves, so the hydrodynamic force vanishes and the contact force balances the external one:
  1. force balance: the contact normal force on each sphere equals F, to 1e-3 relative;
  2. Hertz: the overlap |delta'| = 2a + h_r - |r| equals (F/k_n)^(2/3), to 1e-3 relative (it
     follows from 1 through the 2/3 power, so the same tolerance is generous by 3/2);
  3. the velocities vanish: |U| < 1e-4 a gamma_dot (the free approach starts at 0.46);
  4. frictionless: the tangential part |F - (F.n) n| of the contact force is 0 to round-off
     (1e-12 |F|: n is recomputed here from the positions) and the contact torque is exactly 0;
     action equals reaction exactly; the contact stresslet is symmetric with trace F.r/2.
k_n = 6 pi/(eps_bar h_r)^(3/2) with eps_bar = 0.05 (the value the eps_bar rule gives at shear rate 1;
prescribed here because the box is not sheared): the equilibrium overlap is eps_bar h_r = 5e-4 a.
Time step: Re = 1e-3, dt = 1e-4 keep the explicit Hertz force stable (k_eff dt over the one-step
mobility of the fictitious domain well below 2; Re = 0.01, dt = 1e-3 oscillates at this k_n) and the
viscous relaxation of the box short. radius_offset = 0: the fictitious spheres (radius
a + offset*Delta) must not overlap, otherwise the rigid constraints of both spheres on the shared
faces hold part of the load through lambda and the steady contact force is not unique (with the
default 0.38 the balance stalls 2 % short; measured). Measured convergence: the force deficit is
1.3e-3 after 150 steps and 1.7e-4 after 250. No lubrication correction: this test isolates the
contact force (and no table is calibrated for radius_offset = 0)."""
import math
import os
import numpy as np
import fdsusp_testlib as T

F = 6 * math.pi
EPS_R, EPS_BAR = 0.01, 0.05
KN = 6 * math.pi / (EPS_BAR * EPS_R) ** 1.5
D0 = 2 + EPS_R                     # touching, zero contact force
DECK = """&domain box = 6.4, 4.8, 4.8, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 0 /
&fluid reynolds = 1e-3 /
&time dt = 1e-4, steps = 250 /
&output directory = 'out', progress_every = 50 /
&particles number = 2, radius_offset = 0,
  position(:,1) = {x1!r}, 2.4, 2.4, external_force(:,1) = {f!r}, 0, 0,
  position(:,2) = {x2!r}, 2.4, 2.4, external_force(:,2) = {mf!r}, 0, 0 /
&contact roughness = {eps_r!r}, normal_stiffness = {kn!r}, friction = 0 /
&lubrication model = 'none' /
"""
d = T.scratch('contact_pair_dns')
T.run(T.write_deck(d, 'pair.nml', DECK.format(x1=3.2 - D0 / 2, x2=3.2 + D0 / 2, f=F, mf=-F, eps_r=EPS_R,
                                              kn=KN)), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
fc = s['particles/force_contact']          # records x 2 x 3, computed at the positions before the step
tc = s['particles/torque_contact']
sc = s['particles/stresslet_contact']
x = s['particles/position']                # after the step
u = s['particles/velocity']
last = len(fc) - 1
T.check(np.all(s['contacts_pair'][5:] == 1) and np.all(s['contacts_wall'] == 0),
        'one pair contact from step 6 on, no wall contact')

# 1. force balance
fn = -fc[last, 0, 0]
err = abs(fn - F) / F
T.check(err <= 1e-3, 'force balance: contact normal force %.6f vs F = %.6f (relative %.1e <= 1e-3)' % (fn, F, err))
# 2. Hertz overlap, from the positions at which the last contact force was computed
r = x[last - 1, 1] - x[last - 1, 0]
overlap = D0 - np.linalg.norm(r)
hertz = (F / KN) ** (2.0 / 3.0)
err = abs(overlap - hertz) / hertz
T.check(err <= 1e-3, 'Hertz: overlap %.6e vs (F/k_n)^(2/3) = %.6e (relative %.1e <= 1e-3)' % (overlap, hertz, err))
T.check(abs(s['contact_max_overlap'][last] - overlap) <= 1e-12,
        'the series column contact_max_overlap is that overlap (%.6e)' % s['contact_max_overlap'][last])
# 3. at rest
umax = np.abs(u[last]).max()
T.check(umax < 1e-4, 'velocities vanish: max |U| = %.1e < 1e-4 (approach started at %.2f)' % (umax, np.abs(u[0]).max()))
# 4. frictionless: no tangential force, no torque; action = reaction; stresslet
worst_t = 0.0
for k in range(1, last + 1):
    rk = x[k - 1, 1] - x[k - 1, 0]
    n = rk / np.linalg.norm(rk)
    f = fc[k, 0]
    worst_t = max(worst_t, np.linalg.norm(f - np.dot(f, n) * n) / F)
T.check(worst_t <= 1e-12, 'frictionless: max |F_t|/F over the run = %.1e <= 1e-12' % worst_t)
T.check(np.all(tc == 0), 'frictionless: the contact torque is exactly 0')
T.check(np.array_equal(fc[:, 1], -fc[:, 0]), 'action equals reaction exactly')
S = sc[last, 0]
T.check(np.abs(S - S.T).max() == 0 and abs(np.trace(S) - np.dot(fc[last, 0], r) / 2) <= 1e-12 * F,
        'contact stresslet symmetric, trace %.6f = F.r/2' % np.trace(S))
T.finish()
