"""Invariant: a stress that varies in time (doc/INPUT.md "&shear": control = 'stress' with protocol
'oscillatory' or 'reversal'; issue 46) is met at every step, and the rate it sets is the
suspension's answer to it.
A. Frozen spheres (motion 'frozen', 38 spheres, phi 0.3, walls 8a apart, lubrication dynamics):
   their stress is linear in the rate with no other term (no motion, no contact), Sigma_xy =
   eta_f gamma_dot, so a stress oscillation S0 sin(omega t) must give the rate S0 sin(omega t_n) /
   eta_f at every step -- a purely viscous response (G' = 0, G''/omega = eta_f), in phase with the
   stress. eta_f is measured by a rate-controlled run of the same configuration (its stress at
   rate 1, constant at every record to 1e-12). Checks: the stress of each step is S0 sin(omega
   t_n) (1e-12 of S0: the same formula, t_n summed step by step); the rate is stress/eta_f at every
   record (1e-10 relative: two 6N solves of the same matrix, each to CG's 1e-12, and the affine
   split, measured ~1e-13); the first-harmonic fit of stress against rate gives the viscosity eta_f
   and no elastic part (the rate's quadrature component over its amplitude < 1e-10).
B. A reversal of the stress in a frictional suspension (49 rough spheres, phi 0.4, mu_d 0.5,
   Lees-Edwards 8a box, S = 10, about the stress of rate 1; G = 2 strains, 1000 steps): the
   stress is +-S at every record, its sign flipping when the accumulated |strain| (the sum of
   |advance| dt, the spheres' Adams-Bashforth strain) first reaches kG, at no other step; the
   rate has the sign of the stress throughout; and the physics of a reversal (Gadala-Maria &
   Acrivos 1980; Blanc, Peters & Lemaire 2011; doc/VALIDATION.md §12.4 under rate control): the
   contact network built in one direction gives way when the stress turns, so right after the
   first reversal (from the sheared state of the first 2 strains) the suspension is less viscous:
   the mean |rate| over the first 0.2 strain after it exceeds the mean over the second half of
   the segment before it by more than 20 % (measured x1.48: eta 8.9 -> 6.0; under rate control
   the same scene's viscosity is 8.8 before and 6.0 right after). Only the first: reversals every
   2 strains (a strain amplitude of 1) organise this suspension (Corte et al., Nature Phys. 2008)
   -- by the 5th segment the contact viscosity is ~1 instead of ~5, under stress control and
   under rate control alike (measured 2026-11-28), and later reversals change little.
C. The DNS's fluid alone between walls (4a cube, a/Delta 2, Re 0.01, backward Euler, dt 0.01) under
   the stress 2.5 sin(2 pi t): the mean wall stress is the target at every record (1e-12 of S0: the
   step plus a multiple of its unit wall-speed response), both walls alike; over the last two
   periods the rate's first harmonic has the amplitude S0/eta (within 2 %) and lags the stress by
   a small positive angle (the fluid's inertia: omega times the gap's viscous time Re Ly^2/pi^2 is
   0.10, and backward Euler adds omega dt/2 = 0.03; bound (0, 0.15) rad; measured 0.99, 0.082).
20 seconds on one core."""
import os
import numpy as np
import fdsusp_testlib as T

FROZEN = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'walls' /
&shear {shear} /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = '{out}', progress_every = 100000 /
&particles solid_fraction = 0.3, seed = 2, motion = 'frozen' /
&rheology discard_strain = 0.0, average_strain = {average}, blocks = 2 /
"""
REVERSAL = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear control = 'stress', stress = 10.0, protocol = 'reversal', reversal_strain = 2.0 /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = 1000 /
&output directory = 'reversal', progress_every = 100000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = 4.0, blocks = 2 /
"""
DT, S0, PERIOD = 5.0e-3, 2.0, 0.5

d = T.scratch('protocol_stress_varying')
FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear control = 'stress', stress = 2.5, protocol = 'oscillatory', period = 1.0 /
&fluid reynolds = 0.01, viscous_theta = 1.0 /
&time dt = 1.0e-2, steps = 300 /
&output directory = 'fluid', progress_every = 1000 /
"""

# The four runs are independent of one another (the oscillation's deck does not need eta_f, only
# its checks do; each run has its own output directory): run together, two at a time
T.run_many([
    dict(deck=T.write_deck(d, 'osc.nml', FROZEN.format(shear="control = 'stress', stress = %r, protocol = 'oscillatory', "
                                                          "period = %r" % (S0, PERIOD), steps=400, out='osc',
                                                          average=1.0)), cwd=d),
    dict(deck=T.write_deck(d, 'reversal.nml', REVERSAL), cwd=d),
    dict(deck=T.write_deck(d, 'rate.nml', FROZEN.format(shear='rate = 1.0', steps=20, out='rate', average=0.1)), cwd=d),
    dict(deck=T.write_deck(d, 'fluid.nml', FLUID), cwd=d)])

# A. frozen spheres: eta_f from rate control, then an oscillation of the stress
s = T.series(os.path.join(d, 'rate'))
sigma = s['shear/rate'] + s['core/stress_hydro'][:, 3] + s['core/stress_contact'][:, 3]
eta_f = sigma.mean()
T.check(np.ptp(sigma) <= 1e-12 * eta_f and eta_f > 1.0,
        'frozen spheres at rate 1: the stress is eta_f = %.6f at every record (spread %.1e)' % (eta_f, np.ptp(sigma)))

s = T.series(os.path.join(d, 'osc'))
t_n = (s['step'] - 1) * DT
target = S0 * np.sin(2 * np.pi * t_n / PERIOD)
miss = np.max(np.abs(s['shear/stress'] - target)) / S0
T.check(miss <= 1e-12, 'stress oscillation: the stress of each step is S0 sin(omega t_n) (%.1e of S0)' % miss)
rate = s['shear/rate']
miss = np.max(np.abs(rate * eta_f - s['shear/stress'])) / S0
T.check(miss <= 1e-10, 'frozen spheres: the rate is stress/eta_f at every record, a viscous response (%.1e of S0)' % miss)
# first harmonic of the rate against the stress's phase: in phase (viscous), no quadrature (elastic)
phase = 2 * np.pi * t_n / PERIOD
whole = t_n < np.floor(t_n[-1] / PERIOD) * PERIOD          # whole periods only
basis = np.column_stack([np.sin(phase[whole]), np.cos(phase[whole])])
(in_phase, quadrature), *_ = np.linalg.lstsq(basis, rate[whole], rcond=None)
T.check(abs(S0 / in_phase - eta_f) <= 1e-10 * eta_f and abs(quadrature) <= 1e-10 * abs(in_phase),
        'frozen spheres: |G*|/omega = S0/rate amplitude = %.6f = eta_f, the elastic part %.1e of it'
        % (S0 / in_phase, abs(quadrature / in_phase)))

# B. a reversal of the stress in a frictional suspension
s = T.series(os.path.join(d, 'reversal'))
stress, rate = s['shear/stress'], s['shear/rate']
T.check(np.all(np.abs(np.abs(stress) - 10.0) <= 1e-12 * 10.0), 'reversal: the stress is +-10 at every record')
# the accumulated |strain| at the start of each record's step, from the strain the spheres advanced
advanced = np.abs(np.diff(s['shear/strain']))
travel = np.r_[0.0, np.cumsum(advanced)]
flips = np.flatnonzero(np.sign(stress[1:]) != np.sign(stress[:-1])) + 1
# the flip of record n happens at the start of its step, when travel (at that start) reaches kG
expected = [int(np.argmax(travel >= k * 2.0 - 1e-9 * 5e-2)) for k in range(1, 20) if travel[-1] >= k * 2.0]
T.check(len(flips) >= 2 and list(flips) == expected and stress[0] > 0,
        'reversal: the stress flips at the records where the accumulated |strain| reaches 2, 4, ... (%s; expected %s)'
        % (list(flips), expected))
T.check(np.all(np.sign(rate) == np.sign(stress)), 'reversal: the rate has the sign of the stress at every record')
f = flips[0]
index = np.arange(len(rate))
before = np.abs(rate[(index < f) & (travel >= 0.5 * travel[f])]).mean()
after = np.abs(rate[(index >= f) & (travel < travel[f] + 0.2)]).mean()
T.check(after / before > 1.2, 'reversal: the suspension gives way after the first reversal, mean |rate| over the first '
        '0.2 strain %.3f against %.3f before (x%.2f > 1.2; eta %.2f -> %.2f)' % (after, before, after / before,
                                                                          10.0 / before, 10.0 / after))

# C. the fluid alone under an oscillating wall stress (run above)
s = T.series(os.path.join(d, 'fluid'))
t_n = (s['step'] - 1) * 1.0e-2
target = 2.5 * np.sin(2 * np.pi * t_n)
tau = 0.5 * (s['tau_wall_bottom'] + s['tau_wall_top'])
miss = max(np.max(np.abs(tau - target)), np.max(np.abs(s['tau_wall_bottom'] - s['tau_wall_top'])),
           np.max(np.abs(s['shear/stress'] - target))) / 2.5
T.check(miss <= 1e-12, 'fluid: the mean wall stress is 2.5 sin(2 pi t_n) at every record, both walls alike (%.1e)' % miss)
late = t_n >= 1.0 - 1e-9
basis = np.column_stack([np.sin(2 * np.pi * t_n[late]), np.cos(2 * np.pi * t_n[late])])
(in_phase, quadrature), *_ = np.linalg.lstsq(basis, s['shear/rate'][late], rcond=None)
amplitude, lag = np.hypot(in_phase, quadrature) / 2.5, -np.arctan2(quadrature, in_phase)
T.check(abs(amplitude - 1) <= 0.02 and 0 < lag < 0.15,
        'fluid: the rate follows the stress with amplitude S0/eta x %.4f and a lag of %.3f rad (inertia)' % (amplitude, lag))
T.finish()
