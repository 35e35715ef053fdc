"""Invariant: a suspension oscillated at a small strain amplitude is a viscous liquid of its frozen
configuration (doc/RHEOLOGY.md "Protocols"; issue 46). Lubrication dynamics, 37 rough frictionless
spheres (phi 0.3, Lees-Edwards, 8a box), gamma(t) = 0.01 sin(omega t), T = 0.064 = 64 steps,
5 periods (fdsusp.protocols.oscillation_moduli over each period, harmonics 1 and 3):
1. no contact forms (the gaps stay above h_r: every contact count and contact stress is zero), so
   the stress is purely hydrodynamic, eta(X) gamma_dot(t) with the viscosity eta(X) of the
   configuration, which moves by at most gamma_0 Ly/2 = 0.04 a;
2. G''/omega equals that viscosity: it is a weighted mean of the instantaneous ratio
   sigma_xy/gamma_dot (solvent included) over the cycle, so it must lie within the range of that
   ratio over the records where |gamma_dot| > gamma_0 omega/2 (its spread is the configuration's
   change: the tolerance is measured, not chosen), and agree with the ratio of the first record
   (the packing itself at the reference rate: eta at steady rate from the same packing over one
   step) within that spread;
3. G' vanishes within its error: a viscosity that follows the strain, eta(gamma(t)), puts
   gamma_dot(t) eta(gamma(t)) into the even harmonics only; a first harmonic in phase with the
   strain comes from the drift of eta from one period to the next (a linear drift eta' gives
   G' = eta'/2), so |G'| <= 3 x (its error over the periods) + 3 x max|Delta eta per period|/(2T);
4. the spheres come back: the stroboscopic mean-square displacement between cycles (Stokes flow
   is reversible; what remains is the Adams-Bashforth error over a cycle, (omega dt)^2 of the
   largest displacement gamma_0 Ly/2) is below ((omega dt)^2 gamma_0 Ly/2)^2.
About 2 s on one core."""
import math
import numpy as np
import fdsusp_testlib as T
from fdsusp import protocols

GAMMA_0, PERIOD, DT, L = 0.01, 0.064, 1.0e-3, 8.0
DECK = f"""&domain box = {L}, {L}, {L}, y_boundary = 'lees-edwards' /
&shear protocol = 'oscillatory', strain_amplitude = {GAMMA_0}, period = {PERIOD} /
&fluid model = 'none' /
&time dt = {DT}, steps = 320 /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.3, seed = 3 /
&contact roughness = 5.0e-3, friction = 0.0 /
&rheology discard_strain = 0.0, average_strain = 0.3, blocks = 5 /
"""
d = T.scratch('protocol_oscillation')
T.run(T.write_deck(d, 'osc.nml', DECK), d)
out = d + '/out'
s = T.series(out)
omega = 2 * math.pi / PERIOD

# 1. no contacts
T.check(np.all(s['contacts_pair'] == 0) and np.all(s['core/stress_contact'] == 0),
        'no contact forms: contact counts and contact stress zero at every record (smallest gap %.2e a)'
        % s['min_gap'].min())

# 2. G''/omega against the configuration's viscosity
m = protocols.oscillation_moduli(out)
T.check(len(m['periods']) == 5, '5 whole periods analysed (%s)' % m['periods'])
g1, g3 = m[1], m[3]
stress = protocols.stresses(s)['shear']
rate = s['shear/rate']
fast = np.abs(rate) > 0.5 * GAMMA_0 * omega
ratio = stress[fast] / rate[fast]
eta_dyn = g1["G''"][0] / omega
print('G\'\'/omega = %.6f +- %.1e; sigma/gamma_dot in [%.6f, %.6f], first record %.6f; G\'\'_3/omega = %.2e'
      % (eta_dyn, g1["G''"][1] / omega, ratio.min(), ratio.max(), ratio[0], g3["G''"][0] / omega))
T.check(ratio.min() <= eta_dyn <= ratio.max(),
        "G''/omega = %.6f within the range of sigma_xy/gamma_dot over the cycles [%.6f, %.6f]"
        % (eta_dyn, ratio.min(), ratio.max()))
T.check(abs(eta_dyn - ratio[0]) <= ratio.max() - ratio.min(),
        "G''/omega = %.6f against eta of the packing at the reference rate %.6f: |difference| %.1e <= spread %.1e"
        % (eta_dyn, ratio[0], abs(eta_dyn - ratio[0]), ratio.max() - ratio.min()))

# 3. G' vanishes within its error and the drift of eta between periods
phase0 = (s['step'] - 1) % round(PERIOD / DT) == 0
eta0 = stress[phase0] / rate[phase0]
drift = np.max(np.abs(np.diff(eta0)))
bound = 3 * g1["G'"][1] + 3 * drift / (2 * PERIOD)
T.check(abs(g1["G'"][0]) <= bound,
        "G' = %.2e +- %.1e vanishes: |G'| <= 3 err + 3 max|Delta eta per period|/(2T) = %.1e (G'' = %.4g)"
        % (g1["G'"][0], g1["G'"][1], bound, g1["G''"][0]))

# 4. stroboscopic displacement between cycles
msd = protocols.stroboscopic_msd(out, [L, L, L])
limit = ((omega * DT) ** 2 * GAMMA_0 * L / 2) ** 2
T.check(len(msd['msd']) == 4 and np.all(msd['msd'] < limit),
        'the spheres come back each cycle: stroboscopic MSD %s < %.1e a^2' % (np.array2string(msd['msd'], precision=2), limit))
T.finish()
