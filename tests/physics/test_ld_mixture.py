"""Invariant: lubrication dynamics moves a suspension of spheres of two sizes (doc/INPUT.md
"Mixtures"; doc/LUBRICATION.md, doc/RHEOLOGY.md "Spheres of several sizes"). 53 rough frictional
spheres, radii 1 and 1.4 (39 and 14: 50/50 by volume within one sphere), phi = 0.324, placed at
random with numpy (gaps >= 0.05 a) in a 10a Lees-Edwards cube, exact pair hydrodynamics
(&lubrication model = 'full'), 300 steps of dt = 5e-3 (1.5 strains):
1. the run finishes, every per-sphere and core column and the summary's viscosities, normal
   stresses, phi_core and gamma_dot_core are finite, pairs are lubricated and touch;
2. the mean velocity stays affine: the spheres' mean disturbance velocity <U - U_inf(y)> over the
   run and over its last 100 steps is within 3 sigma/sqrt(N) in every component, sigma the
   spheres' velocity fluctuation (no conservation law makes it zero: the pair links exert a net
   drag; measured 0.027 against the bound 0.18, steady from the first to the last third), and the
   particle phase shears at gamma_dot within 10 % (gamma_dot_core measured 1.028);
3. phi_core counts each sphere's own volume: in the Lees-Edwards box (every sphere whole) the
   column core/solid_fraction equals sum (4/3) pi a_i^3 / V at every record, and between walls a
   static configuration (motion 'fixed', 19 spheres cut by the core's edges, 19 wall links) has
   phi_core = sum_i V_i(core) / V_core with each sphere's slab volume of its own radius, computed
   here independently; 1e-12 relative (round-off of ~50 terms; measured 7e-16);
4. the run on 2 ranks (each evaluates a share of the pair links, gathered in order,
   mod_lubrication_links; the 6N system solved on a distributed matrix, doc/DESIGN.md
   "Parallelism") writes the same series.h5 (wall_time excepted) to 1e-9 of each entry's largest
   magnitude: CG stops at a relative residual of 1e-12 and its sums are regrouped on 2 ranks, and
   over 300 steps of a dense frictional suspension the stiff contacts amplify that round-off
   (measured 3e-11, in the contact forces); a row set by the wrong rank or lost differs at O(1);
5. the statistics per species (doc/RHEOLOGY.md "Per species") exist, are finite and add up to the
   pooled ones: at every record the species' core stresses, phi_core,s and phi_s(y) sum to the
   pooled columns, and in summary.json the species' shares of eta_r - 1, eta_h - 1, eta_c, N1/tau,
   N2/tau, Pi/tau, Pi_h/tau, N1_h/tau and phi_core sum to the pooled quantities, phi_s(y) to phi(y)
   (1e-12 of the largest magnitude: sums of ~50 terms regrouped, measured ~1e-16); g_ab(r) is zero
   closer than contact less 0.05 a (no overlap that deep with eps_r = 5e-3) and g_12 = g_21 in the
   Lees-Edwards box (the same pairs from both ends; 1e-12 relative); scripts/rheology.py redoes
   the species' summary from series.h5 to 1e-10 (--compare; the pooled g(theta) with the mixture's
   mean sphere volume);
6. a mixture restarted at step 150 (inside the first averaging block) from its checkpoint writes
   the same series.h5 (wall_time excepted) and summary.json as the uninterrupted run, bitwise
   (the checkpoint carries the per-species accumulators; the restart is exact);
7. between walls (the static case of 3) the per-species columns include the sampled shell
   volumes of g_ab and phi_s(y) sums to phi(y) (1e-12).
About 12 s."""
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
import numpy as np
import fdsusp_testlib as T

LE = """&domain box = 10, 10, 10, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = 300 /
&output directory = 'out', progress_every = 100 /
&particles radius = 1.0, 1.4, volume_share = 0.5, 0.5, position_file = 'mix.h5' /
&contact roughness = 5e-3, friction = 0.5 /
&lubrication model = 'full' /
&rheology discard_strain = 0.5, average_strain = 1.0, blocks = 2 /
"""
WALLS = """&domain box = 10, 12, 10, y_boundary = 'walls', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = 2 /
&output directory = 'out' /
&particles radius = 1.0, 1.4, volume_share = 0.5, 0.5, position_file = 'mix.h5', motion = 'fixed' /
&lubrication model = 'full' /
&rheology discard_strain = 0.001, average_strain = 0.005, blocks = 1 /
"""


def place(box, radii, walls, seed=3):
    """random sequential placement, largest first, surface gaps >= 0.05 (and off the walls)."""
    rng = np.random.default_rng(seed)
    pos = []
    for a in radii:
        for _ in range(100000):
            lo = np.array([0.0, a + 0.05 if walls else 0.0, 0.0])
            hi = np.array(box) - lo
            x = rng.uniform(lo, hi)
            ok = True
            for p, b in pos:
                d = x - p
                d[0] -= box[0] * np.round(d[0] / box[0])
                d[2] -= box[2] * np.round(d[2] / box[2])
                if not walls:
                    d[1] -= box[1] * np.round(d[1] / box[1])
                if np.linalg.norm(d) < a + b + 0.05:
                    ok = False
                    break
            if ok:
                pos.append((x, a))
                break
        else:
            raise SystemExit('test setup: placement failed')
    return np.array([p for p, _ in pos]), np.array([a for _, a in pos])


def write(d, pos, radii):
    with T.h5py.File(os.path.join(d, 'mix.h5'), 'w') as f:
        f.create_dataset('particles/position', data=pos)
        f.create_dataset('particles/radius', data=radii)


radii = np.array([1.4] * 14 + [1.0] * 39)
volume = 4.0 / 3.0 * np.pi * radii**3

# 1-3: the sheared suspension between Lees-Edwards boundaries
d = T.scratch('ld_mixture')
pos, r = place((10.0, 10.0, 10.0), radii, walls=False)
write(d, pos, r)
# the run of 1-5 on one core while 6's two runs (a restart at step 150, another output directory)
# go on the other
le_run = ThreadPoolExecutor(max_workers=1).submit(T.run, T.write_deck(d, 'le.nml', LE), d)
deck_half = LE.replace("directory = 'out'", "directory = 'out3'").replace('steps = 300', 'steps = 150')
T.run(T.write_deck(d, 'le3.nml', deck_half), d)
T.run(T.write_deck(d, 'le3.nml', deck_half.replace('steps = 150', 'steps = 300')), d, args=['-restart', 'out3/checkpoint.h5'])
status, out, err = le_run.result()
T.check('finished at step 300' in out, 'the mixture runs 300 steps')
s = T.series(os.path.join(d, 'out'))
finite = all(np.isfinite(s[k]).all() for k in s if k.startswith('particles/') or k.startswith('core/'))
T.check(finite, 'every per-sphere and core column is finite')
summary = json.load(open(os.path.join(d, 'out', 'summary.json')))
q = summary['quantities']
T.check(all(np.isfinite(v['value']) for k, v in q.items() if k in ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau',
                                                                    'phi_core', 'gamma_dot_core')),
        'the summary\'s eta_r, eta_h, eta_c, N1, N2, Pi, phi_core, gamma_dot_core are finite (eta_r = %.3f)'
        % q['eta_r']['value'])
T.check(int(np.max(s['lubrication_pairs'])) > 0 and float(np.min(s['min_gap'])) < 0.01,
        'pairs are lubricated (up to %d links) and come into contact (smallest gap %.1e)'
        % (int(np.max(s['lubrication_pairs'])), float(np.min(s['min_gap']))))
gd = q['gamma_dot_core']['value']
T.check(abs(gd - 1) <= 0.1, 'the particle phase shears at gamma_dot_core = %.4f (within 10 %%)' % gd)
phi = volume.sum() / 1000.0
col = s['core/solid_fraction'].ravel()
T.check(float(np.max(np.abs(col / phi - 1))) <= 1e-12, 'Lees-Edwards: core/solid_fraction = sum (4/3) pi a_i^3 / V = %.12f '
        'at every record (max relative difference %.1e <= 1e-12)' % (phi, float(np.max(np.abs(col / phi - 1)))))
# the disturbance velocity U - U_inf(y) of every sphere, its mean over the spheres per record
x = s['particles/position']
dist = np.array(s['particles/velocity'], dtype=float)
dist[:, :, 0] -= x[:, :, 1] - 5.0
bound = 3 * dist.std(axis=(0, 1)).max() / np.sqrt(x.shape[1])
mean = dist.mean(axis=1)
whole = mean.mean(axis=0)
late = mean[-100:].mean(axis=0)
T.check(np.abs(whole).max() <= bound and np.abs(late).max() <= bound,
        'affine mean velocity: <U - U_inf> over the run %s and over the last 100 steps %s within 3 sigma/sqrt(N) = %.3f '
        'gamma_dot a' % (np.array2string(whole, precision=4), np.array2string(late, precision=4), bound))

# 4: two ranks share out the pair links (the unequal pairs' 22/21 scalars gathered with them)
T.run(T.write_deck(d, 'le2.nml', LE.replace("directory = 'out'", "directory = 'out2'")), d, np_ranks=T.RANKS)
T.compare_h5(os.path.join(d, 'out', 'series.h5'), os.path.join(d, 'out2', 'series.h5'), '%d ranks against 1' % T.RANKS,
             skip=('wall_time', 'deck@output.directory'), rtol=1e-9)

# 5: per species
def rel_max(x, y):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return float(np.max(np.abs(x - y)) / max(1.0, float(np.max(np.abs(y)))))


worst = max(rel_max(s['species/stress_hydro'].sum(axis=1), s['core/stress_hydro']),
            rel_max(s['species/stress_contact'].sum(axis=1), s['core/stress_contact']),
            rel_max(s['species/solid_fraction'].sum(axis=1), s['core/solid_fraction'].ravel()),
            rel_max(s['species/profile_solid_fraction'].sum(axis=1), s['profiles/solid_fraction']))
T.check(worst <= 1e-12, 'every record: the species\' core stresses, phi_core,s and phi_s(y) add up to the pooled '
        'columns (max rel. difference %.1e <= 1e-12)' % worst)
sp = summary['species']
T.check(sp['radius'] == [1.0, 1.4] and sp['count'] == [39.0, 14.0], 'summary: species radii %s, counts %s'
        % (sp['radius'], sp['count']))
shares = {'eta_r-1': ('eta_r', 1.0), 'eta_h-1': ('eta_h', 1.0), 'eta_c': ('eta_c', 0.0), 'N1/tau': ('N1/tau', 0.0),
          'N2/tau': ('N2/tau', 0.0), 'Pi/tau': ('Pi/tau', 0.0), 'Pi_h/tau': ('Pi_h/tau', 0.0),
          'N1_h/tau': ('N1_h/tau', 0.0), 'N1_c/tau': ('N1_c/tau', 0.0), 'N2_c/tau': ('N2_c/tau', 0.0),
          'Pi_c/tau': ('Pi_c/tau', 0.0), 'phi_core': ('phi_core', 0.0)}
finite = all(np.isfinite(np.array(sp['quantities'][n][part], dtype=float)).all() for n in shares
             for part in ('value', 'error'))
worst = max(abs(sum(sp['quantities'][n]['value']) - (q[p]['value'] - off)) / max(1.0, abs(q[p]['value']))
            for n, (p, off) in shares.items())
T.check(finite and worst <= 1e-12, 'summary: the species\' shares (value and error finite) add up to the pooled '
        'eta_r - 1, eta_h - 1, eta_c, N1, N2, Pi (parts) and phi_core (max rel. difference %.1e <= 1e-12; eta_r - 1 = '
        '%.3f + %.3f)' % (worst, *sp['quantities']['eta_r-1']['value']))
worst = rel_max(np.sum(sp['profiles']['solid_fraction'], axis=0), summary['profiles']['solid_fraction'])
T.check(worst <= 1e-12, 'summary: phi_1(y) + phi_2(y) = phi(y) (max rel. difference %.1e)' % worst)
pd = sp['pair_distribution']
r_bins = np.array(pd['r'])
g = np.array(pd['g'], dtype=float)
radius = np.array(sp['radius'])
inside = all(np.all(g[a, b][r_bins + 0.5 * pd['radial_width'] < radius[a] + radius[b] - 0.05] == 0)
             for a in range(2) for b in range(2))
T.check(np.isfinite(g).all() and inside and g.shape == (2, 2, len(r_bins)) and r_bins[-1] > 4.5,
        'g_ab(r) finite up to r = %.2f a, zero inside contact less 0.05 a; first peaks %s' %
        (r_bins[-1] + 0.5 * pd['radial_width'],
         ', '.join('g_%d%d %.1f at %.3f' % (a + 1, b + 1, g[a, b].max(), r_bins[np.argmax(g[a, b])])
                   for a, b in ((0, 0), (0, 1), (1, 1)))))
sym = float(np.max(np.abs(g[0, 1] - g[1, 0]) / np.maximum(1.0, g[0, 1])))
T.check(sym <= 1e-12, 'Lees-Edwards: g_12 = g_21 (max rel. difference %.1e <= 1e-12)' % sym)
p = subprocess.run([sys.executable, os.path.join(T.ROOT, 'scripts', 'rheology.py'), os.path.join(d, 'out'), '--compare'],
                   capture_output=True, text=True)
T.check(p.returncode == 0 and 'agrees to 1e-10' in p.stdout, 'scripts/rheology.py reproduces summary.json with its '
        'species object to 1e-10 (%s)' % (p.stdout.strip().splitlines()[-1] if p.stdout.strip() else p.stderr[-300:]))

# 6: a restart at step 150 from the checkpoint (run above)
T.compare_h5(os.path.join(d, 'out', 'series.h5'), os.path.join(d, 'out3', 'series.h5'), 'mixture restarted at step 150',
             skip=('wall_time', 'deck@output.directory'), rtol=0)
with open(os.path.join(d, 'out3', 'summary.json')) as f:
    restarted = json.load(f)
T.check(restarted['species'] == summary['species'] and restarted['quantities'] == summary['quantities'],
        'mixture restarted at step 150: summary.json (species object and quantities) identical')

# 3: a static configuration between walls, phi_core from each sphere's own slab volume
d = T.scratch('ld_mixture_walls')
pos, r = place((10.0, 12.0, 10.0), radii, walls=True)
write(d, pos, r)
status, out, err = T.run(T.write_deck(d, 'walls.nml', WALLS), d)
s = T.series(os.path.join(d, 'out'))
t1 = np.maximum(3.0 - pos[:, 1], -r)
t2 = np.minimum(9.0 - pos[:, 1], r)
inside = np.where(t2 > t1, np.pi * (r**2 * (t2 - t1) - (t2**3 - t1**3) / 3.0), 0.0)
expect = inside.sum() / (10.0 * 6.0 * 10.0)
got = s['core/solid_fraction'].ravel()
cut = int(np.sum((inside > 0) & (inside < 4.0 / 3.0 * np.pi * r**3 * (1 - 1e-12))))
T.check(float(np.max(np.abs(got / expect - 1))) <= 1e-12 and cut > 0,
        'walls, static: phi_core = sum_i V_i(core) / V_core = %.12f with each sphere\'s own radius (%d spheres cut by '
        'the core\'s edges; max relative difference %.1e <= 1e-12)' % (expect, cut, float(np.max(np.abs(got / expect - 1)))))
T.check(int(np.max(s['lubrication_walls'])) > 0, 'walls: %d sphere-wall links' % int(np.max(s['lubrication_walls'])))
# 7: the per-species columns between walls
worst = rel_max(s['species/profile_solid_fraction'].sum(axis=1), s['profiles/solid_fraction'])
T.check('species/pair_volumes' in s and worst <= 1e-12 and float(np.min(s['species/pair_volumes'])) >= 0,
        'walls: the sampled shell volumes of g_ab are written, phi_1(y) + phi_2(y) = phi(y) (max rel. difference %.1e)'
        % worst)
T.finish()
