"""Invariant: shear reversal (doc/INPUT.md "&shear", protocol 'reversal'; issue 46). Lubrication
dynamics, 49 rough frictional spheres (phi 0.4, eps_r 5e-3, mu_d 0.5, Lees-Edwards, 8a box),
rate 1 reversed every strain G = 1 (200 steps of dt 5e-3), 600 steps:
1. the rate flips at the programmed strains and nowhere else: the records whose rate has the sign
   opposite to the one before are those of the steps from t = 1 and t = 2 (steps 201 and 401),
   |rate| stays 1, and shear/strain is the triangle wave between 0 and G (to 1e-12: sums of 200
   steps of 5e-3);
2. the contact stress falls to near zero right after a reversal: the contact network built in one
   direction opens when the motion reverses (the spheres separate before new contacts form),
   while the hydrodynamic stress stays (Gadala-Maria & Acrivos 1980; Peters et al. 2016).
   fdsusp.protocols.reversal_transient averages both reversals: the signed contact shear stress
   at strains 0.02-0.1 after a reversal is below 10 % of its mean over the last 0.1 strain before
   the first reversal ("near zero": measured 0.15 %), and the hydrodynamic shear stress (with the
   solvent) keeps at least half its value;
3. it builds up again: over the last 0.1 strain before the next reversal the contact stress is at
   least 5 times what it was right after (measured 118 times);
4. the strain since a reversal is measured from the turning point when no record holds it: every
   5th record from the third (as series_every 5 would keep records off the reversal step) gives
   the turning strains 1 and 0 (to 1e-12) and, at each strain since reversal it holds, the
   transient of all records (to 1e-12); before, the origin was the first record after the
   reversal, 2 steps (strain 0.01) late.
About 6 s on one core."""
import numpy as np
import fdsusp_testlib as T
from fdsusp import protocols

G, DT = 1.0, 5.0e-3
DECK = f"""&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear rate = 1.0, protocol = 'reversal', reversal_strain = {G} /
&fluid model = 'none' /
&time dt = {DT}, steps = 600 /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = 3.0, blocks = 3 /
"""
d = T.scratch('protocol_reversal')
T.run(T.write_deck(d, 'rev.nml', DECK), d)
out = d + '/out'
s = T.series(out)
rate, strain, step = s['shear/rate'], s['shear/strain'], s['step']

# 1. the programmed reversals
flips = step[1:][np.sign(rate[1:]) != np.sign(rate[:-1])]
T.check(list(flips) == [201, 401], 'the rate flips at the records of the steps from t = 1 and 2: %s' % list(flips))
T.check(np.all(np.abs(rate) == 1.0) and rate[0] == 1.0, '|rate| = 1 at every record, the first direction +')
n = step - 1                                   # steps before the record's configuration
inside = n % 200
triangle = np.where((n // 200) % 2 == 0, inside, 200 - inside) * DT
err = np.max(np.abs(strain - triangle))
T.check(err < 1e-12, 'shear/strain is the triangle wave between 0 and G (%.1e < 1e-12)' % err)

# 2. the contact stress right after a reversal
r = protocols.reversal_transient(out)
T.check(list(r['reversal_steps']) == [201, 401] and r['count'][1] == 2, 'two reversals averaged')
x = r['strain']
after = (x >= 0.02 - 1e-9) & (x <= 0.1 + 1e-9)
late = (x >= 0.9 - 1e-9)
sc = protocols.stresses(s)
sign = np.sign(rate)
before = (n >= 180) & (n < 200)
c_before = np.mean(sc['shear_c'][before] * sign[before])
h_before = np.mean(sc['shear_h'][before] * sign[before])
c_after = np.mean(r['shear_c']['mean'][after])
h_after = np.mean(r['shear_h']['mean'][after])
c_late = np.mean(r['shear_c']['mean'][late])
print('contact shear stress [eta gamma_dot]: before %.4f, after (0.02-0.1) %.4f +- %.4f, late (0.9-1) %.4f; '
      'hydrodynamic before %.3f, after %.3f' % (c_before, c_after, np.mean(r['shear_c']['error'][after]), c_late,
                                                h_before, h_after))
T.check(c_before > 0 and c_after < 0.1 * c_before,
        'the contact stress falls to near zero after a reversal: %.4f < 10 %% of %.4f' % (c_after, c_before))
T.check(h_after > 0.5 * h_before, 'the hydrodynamic stress stays: %.3f > half of %.3f' % (h_after, h_before))

# 3. and builds up again
T.check(c_late > 5 * c_after, 'the contact stress builds up again: %.4f > 5 x %.4f' % (c_late, c_after))
T.check(all(np.all(np.isfinite(r[k]['mean'])) for k in ('N1', 'N2', 'N1_c', 'N2_c')),
        'N1, N2 and their contact parts against the strain since reversal')

# 4. records that miss the reversal step (series_every > 1)
sub = {k: v[2::5] for k, v in s.items() if k in protocols.STRESS_COLUMNS + ['step']}
rs = protocols.reversal_transient_columns(sub, protocols.settings(out))
turn_err = np.max(np.abs(rs['turning_strain'] - np.array([G, 0.0])))
T.check(turn_err < 1e-12, 'the turning strains from records 2 steps after the reversals: %s (%.1e)'
        % (rs['turning_strain'], turn_err))
k = np.rint(rs['strain'] / DT).astype(int)
T.check(k[0] == 2 and np.all(np.abs(rs['strain'] - k * DT) < 1e-12),
        'the subsampled strains since reversal are 2 + 5 j steps: %s' % rs['strain'][:3])
dev = max(np.nanmax(np.abs(rs[q]['mean'] - r[q]['mean'][k])) for q in ('shear', 'shear_c', 'N1'))
T.check(dev < 1e-12, 'the subsampled transient equals the full one at its strains (%.1e)' % dev)
T.finish()
