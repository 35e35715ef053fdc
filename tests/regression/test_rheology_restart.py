"""Invariants of the suspension statistics (doc/RHEOLOGY.md) on a sheared phi = 0.3 suspension
with every model on (rough frictional contacts, full lubrication), 2 ranks:
 1. summary.json and scripts/rheology.py (the same statistics redone from series.h5 alone) agree
    to 1e-10 relative, for an uninterrupted run and for a restarted one;
 2. a restart in the middle of the averaging window (step 35 of 60, inside block 3 of 5) gives
    the same summary as the uninterrupted run, and every dataset and attribute of the final
    checkpoint (fields, particles, contact springs, rheology/accumulators) and of series.h5 (all
    but wall_time: stresses, pair counts, min_pair_gap, profiles) equals the uninterrupted run's:
    the checkpoint carries the accumulators, the pair counts do not depend on when a neighbour
    list was built (the restart builds a fresh one), and the restart is exact, so 1e-12 of each
    entry's largest magnitude (bitwise in practice);
 3. two independent paths of the code agree: the profile phi(y), integrated over the gap, is the
    volume of all spheres over the box (exact slab volumes per bin; to 1e-12), and averaged over
    the bins of the core (the bins align with y = Ly/4, 3Ly/4) it is phi_core (slab volumes per
    core; to 1e-12) at every record;
 4. the particle snapshots exist with their XDMF series;
 5. a restart keeps the averaging window its checkpoint was accumulated over: from the step-35
    checkpoint, a deck with another average_strain (blocks of 20 steps where 10 were begun) is
    refused before any step, naming the accumulators and &rheology, and the checkpoint is left
    as it was (bitwise); a deck whose window begins after the checkpoint (discard_strain 0.08,
    step 40 > 35) starts the statistics afresh, and its summary.json is what scripts/rheology.py
    computes from series.h5 for that window (1e-10 as in 1: restored accumulators of the old window
    would add the records of steps 11-35 and differ at O(1));
 6. scripts/rheology.py --window recomputes another window from series.h5: on the extended run's
    series, the original window (discard 0.02, average 0.1, 5 blocks) gives the uninterrupted
    run's summary.json (1e-10: the series agree up to step 60, the restart being exact, 2).
Set-up: 8a x 20a x 8a Couette cell, a/Delta = 4, 92 spheres packed at start (seed 2), dt = 2e-3,
10 steps discarded and 5 blocks of 10 steps; eps_bar = 0.1 keeps the contacts below their chatter
limit at this step (doc/CONTACT.md), and packing_min_gap = h_r/2 (instead of the contact-free
default h_r) lets contacts take part from the start. Rounding between the Fortran sums and numpy's
pairwise sums is ~1e-15 relative, hence the 1e-10 of (1)."""
import json
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

import fdsusp_testlib as T

DECK = """&domain box = 8, 20, 8, cells_per_radius = 4, shear_rate = 1 /
&fluid initial_flow = 'shear' /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 5, particles_every = 20 /
&particles solid_fraction = 0.3, seed = 2, packing_min_gap = 2.5e-3 /
&contact roughness = 5e-3, eps_bar = 0.1, friction = 0.5 /
&rheology discard_strain = {discard}, average_strain = {average}, blocks = 5 /
"""
RHEOLOGY = os.path.join(T.ROOT, 'scripts', 'rheology.py')


def summary(d):
    with open(os.path.join(d, 'out', 'summary.json')) as f:
        return json.load(f)


def flat(s):
    """Every number of a summary, in a fixed order."""
    vals = []
    for n in sorted(s['quantities']):
        vals += [s['quantities'][n]['value'], s['quantities'][n]['error']]
    for group, keys in (('profiles', ('solid_fraction', 'velocity')), ('pair_distribution', ('g', 'g_contact'))):
        for k in keys:
            vals += s[group][k]
    return np.array([np.nan if v is None else v for v in vals], dtype=float)


a = T.scratch('rheology_restart_a')
b = T.scratch('rheology_restart_b')
T.run(T.write_deck(a, 'deck.nml', DECK.format(steps=60, discard=0.02, average=0.1)), a, np_ranks=T.RANKS)
T.run(T.write_deck(b, 'deck.nml', DECK.format(steps=35, discard=0.02, average=0.1)), b, np_ranks=T.RANKS)
sb_partial = summary(b)
T.check(sb_partial['blocks_complete'] == 2 and not sb_partial['complete'],
        'the run stopped at step 35 reports 2 complete blocks of 5 (%d)' % sb_partial['blocks_complete'])
# (5) the step-35 checkpoint in a copy c, before b continues from it
c = T.scratch('rheology_restart_c')
shutil.rmtree(os.path.join(c, 'out'), ignore_errors=True)
shutil.copytree(os.path.join(b, 'out'), os.path.join(c, 'out'))
T.run(T.write_deck(b, 'deck.nml', DECK.format(steps=60, discard=0.02, average=0.1)), b, np_ranks=T.RANKS, args=['-restart', 'out/checkpoint.h5'])

for d, name in ((a, 'uninterrupted'), (b, 'restarted')):
    p = subprocess.run([sys.executable, RHEOLOGY, os.path.join(d, 'out'), '--compare'], capture_output=True, text=True)
    T.check(p.returncode == 0 and 'agrees to 1e-10' in p.stdout,
            '%s run: scripts/rheology.py reproduces summary.json to 1e-10' % name)
    if p.returncode != 0:
        print(p.stdout[-2000:], p.stderr[-2000:])

T.compare_h5(os.path.join(a, 'out', 'checkpoint.h5'), os.path.join(b, 'out', 'checkpoint.h5'),
             'restart at step 35, final checkpoint')
T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'), 'restart at step 35, series',
             skip=('wall_time',))
sa, sb = summary(a), summary(b)
T.check(sa['complete'] and sa['blocks_complete'] == 5, 'uninterrupted run: 5 complete blocks')
fa, fb = flat(sa), flat(sb)
same_nan = np.array_equal(np.isnan(fa), np.isnan(fb))
rel = np.nanmax(np.abs(fa - fb) / np.maximum(np.abs(fa), 1e-300))
T.check(same_nan and rel <= 1e-12, 'restart at step 35 gives the same summary (max rel. diff %.1e <= 1e-12; '
        'eta_r = %.4f +- %.4f)' % (rel, sa['quantities']['eta_r']['value'], sa['quantities']['eta_r']['error']))
T.check(sa['quantities']['eta_c']['value'] > 0 and sa['quantities']['I_v']['value'] is not None,
        'contacts take part (eta_c = %.3g, I_v = %s)' % (sa['quantities']['eta_c']['value'], sa['quantities']['I_v']['value']))

with h5py.File(os.path.join(a, 'out', 'series.h5'), 'r') as f:
    prof = f['profiles/solid_fraction'][()]
    core = f['core/solid_fraction'][()]
    n = f['particles/position'].shape[1]
    box = [float(f.attrs[k][0]) for k in ('box_x', 'box_y', 'box_z')]
phi_bulk = n * 4.0 / 3.0 * np.pi / np.prod(box)
err_total = np.abs(prof.mean(axis=1) / phi_bulk - 1).max()
T.check(err_total <= 1e-12, 'phi(y) integrates to the spheres\' volume at every record (max rel. err %.1e)' % err_total)
nb = prof.shape[1]
err_core = np.abs(prof[:, nb // 4: 3 * nb // 4].mean(axis=1) / core - 1).max()
T.check(err_core <= 1e-12, 'phi(y) over the core bins is phi_core at every record (max rel. err %.1e)' % err_core)
for step in (20, 40, 60):
    T.check(os.path.exists(os.path.join(a, 'out', 'particles_%08d.h5' % step)), 'particle snapshot at step %d' % step)
with open(os.path.join(a, 'out', 'particles.xmf')) as f:
    T.check(f.read().count('Polyvertex') == 3, 'particles.xmf lists the three snapshots')
# (5) another window: refused once begun, afresh when it begins after the checkpoint
checkpoint_c = os.path.join(c, 'out', 'checkpoint.h5')
before = open(checkpoint_c, 'rb').read()
status, out, err = T.run(T.write_deck(c, 'deck.nml', DECK.format(steps=60, discard=0.02, average=0.2)), c, np_ranks=T.RANKS,
                         args=['-restart', 'out/checkpoint.h5'], expect_ok=False)
T.check(status != 0 and 'rheology/accumulators' in err and 'blocks begun cannot be cut anew' in err
        and '&rheology' in err and not any(line.startswith('step ') for line in out.splitlines()),
        'a restart with another average_strain over a begun window is refused before any step (%d): %s'
        % (status, err.strip()[-300:]))
T.check(open(checkpoint_c, 'rb').read() == before, 'the refused restart leaves its checkpoint bitwise as it was')
T.run(T.write_deck(c, 'deck.nml', DECK.format(steps=90, discard=0.08, average=0.1)), c, np_ranks=T.RANKS,
      args=['-restart', 'out/checkpoint.h5'])
sc = summary(c)
T.check(sc['complete'] and sc['discard_step'] == 40 and sc['block_steps'] == 10,
        'the restart with discard_strain 0.08 averages steps 41-90 in 5 blocks of 10 (discard %d, blocks of %d)'
        % (sc['discard_step'], sc['block_steps']))
p = subprocess.run([sys.executable, RHEOLOGY, os.path.join(c, 'out'), '--compare'], capture_output=True, text=True)
T.check(p.returncode == 0 and 'agrees to 1e-10' in p.stdout,
        'a window begun after the checkpoint: summary.json is scripts/rheology.py\'s recomputation for it (1e-10)')
if p.returncode != 0:
    print(p.stdout[-2000:], p.stderr[-2000:])
# (6) --window on the extended series gives back the original window's summary
window_json = os.path.join(c, 'window.json')
p = subprocess.run([sys.executable, RHEOLOGY, os.path.join(c, 'out'), '--window', '0.02', '0.1', '5', '--json', window_json],
                   capture_output=True, text=True)
T.check(p.returncode == 0, 'scripts/rheology.py --window --json runs (%s)' % p.stderr.strip()[-200:])
if p.returncode == 0:
    with open(window_json) as f:
        fw = flat(json.load(f))
    rel = np.nanmax(np.abs(fw - fa) / np.maximum(np.abs(fa), 1e-300))
    T.check(np.array_equal(np.isnan(fw), np.isnan(fa)) and rel <= 1e-10,
            '--window 0.02 0.1 5 on the extended series gives the uninterrupted run\'s summary (max rel. diff %.1e)' % rel)
T.finish()
