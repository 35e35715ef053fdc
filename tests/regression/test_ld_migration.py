"""Invariant: spheres that cross the faces of the ranks' z-slabs keep what they carry, so lubrication
dynamics gives one rank's motion on any number of ranks however far the spheres travel along z. On
several ranks the state between steps is each rank's local set (mod_ld_local, doc/DESIGN.md
"Parallelism"): a sphere whose centre leaves its rank's slab migrates to its new owner with its
velocities, its Adams-Bashforth history and its external load, and the contacts' springs go to the
ranks of the spheres they touch; the replicated view is brought up to date only when the output
reads it. In the sheared box the spheres hardly move along z (the vorticity direction: in
test_ld_rank_independence few cross a face), so this scene pushes them across: every sphere
carries the same external force F along z, a drift of about F/(4 pi eta a) (36 a gamma_dot: the
one-body drag, less the pairs' shared drag within the lubrication cut-off), 0.07a a step: the
local sets, kept while no sphere has moved half the skin (0.1a) along z, are made again about
every other step, so that both paths alternate.
Scene: 55 rough frictional spheres (phi 0.45, mu 0.5) in a Lees-Edwards cube of 8 a, 40 steps, the
series recorded every 10 steps; a drift of 4.3a over the run, 1.6 slab widths on 3 ranks.
 1. the spheres do cross: between consecutive records every sphere changes slab on 3 ranks at least
    once, while frictional contacts hold springs;
 2. 2 and 3 ranks against 1 at every record: positions, velocities, omega, hydrodynamic and contact
    stresslets; and the final checkpoint's springs (pairs and values).
Tolerance, as test_ld_rank_independence: 1e-10 of each quantity's largest (measured 2026-11-29: at
most 2.4e-12, the contact stresslets); the sparse solve converges to a relative residual of 1e-12
and sums in another order on more ranks. A sphere that arrived without its Adams-Bashforth history
or a spring lost in a migration changes a velocity or a contact force at O(1)."""
import os
import re
import numpy as np
import h5py
import fdsusp_testlib as T

L = 8.0
STEPS, EVERY, DT = 60, 10, 2e-3
F = 450.0
PACK = """&domain box = {L}, {L}, {L}, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = 1 /
&output directory = 'out' /
&particles solid_fraction = 0.45, seed = 3 /
&contact roughness = 5e-3, friction = 0.5 /
&run title = 'the configuration of test_ld_migration' /
""".format(L=L)
DECK = """&domain box = {L}, {L}, {L}, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = {dt}, steps = {steps} /
&output directory = 'out', progress_every = 10, series_every = {every} /
&particles number = {n},
{spheres} /
&contact roughness = 5e-3, friction = 0.5 /
&run title = 'spheres drifting across the slabs' /
"""
QUANTITIES = ['particles/position', 'particles/velocity', 'particles/omega', 'particles/stresslet_hydro',
              'particles/stresslet_contact']

# the configuration: a packing after one step (the deck's inline spheres)
d = T.scratch('ld_migration_pack')
T.run(T.write_deck(d, 'pack.nml', PACK), d)
with h5py.File(os.path.join(d, 'out', 'checkpoint.h5'), 'r') as f:
    x0 = f['particles/position'][...]
n = len(x0)


def deck(force):
    lines = ',\n'.join('  position(:,%d) = %.15g, %.15g, %.15g, external_force(:,%d) = 0, 0, %.15g'
                       % (i + 1, x[0], x[1], x[2], i + 1, force) for i, x in enumerate(x0))
    return DECK.format(L=L, dt=DT, steps=STEPS, every=EVERY, n=n, spheres=lines)


runs = {'drift_1': (F, 1), 'drift_2': (F, 2), 'drift_3': (F, 3)}
dirs = {name: T.scratch('ld_migration_' + name) for name in runs}
logs = dict(zip(runs, T.run_many([dict(deck=T.write_deck(dirs[name], 'd.nml', deck(force)), cwd=dirs[name],
                                         np_ranks=ranks) for name, (force, ranks) in runs.items()])))
S = {name: T.series(os.path.join(dirs[name], 'out')) for name in runs}
T.check(len(S['drift_1']['time']) == STEPS // EVERY, '%d records (%d)' % (STEPS // EVERY, len(S['drift_1']['time'])))


def largest_difference(a, b):
    return np.abs(a - b).max() / (np.abs(b).max() or 1.0)


# 1. the spheres cross the slab faces, with springs held
drift = S['drift_1']
z = np.concatenate([x0[None, :, 2], drift['particles/position'][:, :, 2]])
slab = np.minimum(2, np.floor(3 * (z % L) / L).astype(int))
moved = (np.diff(slab, axis=0) != 0).any(axis=0)
T.check(moved.all(), 'every sphere changes slab on 3 ranks during the run (%d of %d)' % (moved.sum(), n))
with h5py.File(os.path.join(dirs['drift_1'], 'out', 'checkpoint.h5'), 'r') as f:
    springs1 = int(f['contacts'].attrs['count'][0])
    keys1 = f['contacts/ids'][...] if springs1 else None
    ups1 = f['contacts/spring'][...] if springs1 else None
T.check(springs1 > 0, 'frictional contacts hold springs at the end (%d)' % springs1)

# the sets are kept while no sphere has moved half the skin (0.1a) along z, and made again after:
# at ~0.07a a step, about every other step, so the run mixes both
for ranks in (2, 3):
    m = re.search(r'the sets made (\d+) times in (\d+) steps', logs['drift_%d' % ranks][1])
    made = int(m.group(1)) if m else -1
    T.check(STEPS // 4 <= made <= 3 * STEPS // 4, '%d ranks: the local sets made %d times in %d steps (kept in '
            'between)' % (ranks, made, STEPS))

# 2. 2 and 3 ranks against 1
for ranks in (2, 3):
    other = S['drift_%d' % ranks]
    for k in QUANTITIES:
        e = largest_difference(other[k], drift[k])
        T.check(e <= 1e-10, '%d ranks vs 1: %s (%.1e of its largest)' % (ranks, k, e))
    with h5py.File(os.path.join(dirs['drift_%d' % ranks], 'out', 'checkpoint.h5'), 'r') as f:
        count = int(f['contacts'].attrs['count'][0])
        same = count == springs1 and np.array_equal(f['contacts/ids'][...], keys1)
        e = largest_difference(f['contacts/spring'][...], ups1) if same else np.inf
    T.check(same and e <= 1e-10, '%d ranks vs 1: the final springs, %d pairs (%d), values within %.1e'
            % (ranks, springs1, count, e))
T.finish()
