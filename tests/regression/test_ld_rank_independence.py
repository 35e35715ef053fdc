"""Invariant: lubrication dynamics gives the same motion on any number of ranks. Since issue 45's
first step the 6N particle system is solved in parallel (its block rows shared out over the ranks,
doc/DESIGN.md "Parallelism"), so this is no longer true by construction (before, every rank solved
the same sequential system). Scene: ~250 rough frictional spheres at phi 0.4 in a Lees-Edwards cube
(the bench deck's physics), 40 steps, so that lubrication and contact blocks couple the spheres and
the sparse solve runs at every step.
 1. one rank solves on a sequential matrix (seqbaij), two and three ranks on a distributed one
    (mpibaij), as -particles_ksp_view reports;
 2. 2 and 3 ranks (unequal shares on 3) agree with 1 rank at every step: positions, velocities,
    angular velocities, hydrodynamic and contact stresslets, and the statistics' samples (core
    stresses, the particle velocity fit, pair counts, Q6, the smallest gap) within 1e-10 of each
    quantity's largest magnitude;
 3. 20 steps on 2 ranks, a checkpoint, 20 more on 3 agree with the 40 on 1 rank, likewise; 20 more
    on 2 ranks equal the 40 on 2 bitwise (the checkpoint keeps the ranks' local sets);
 4. the lubrication links stay on the ranks that evaluated them (mod_lubrication_links, issue 45):
    one rank holds all the pair links of the last step (the run log's count), on 2 and 3 ranks
    none does, each holding at least its share; the series' count of pair links (the whole
    system's) is 1 rank's at every step.
 5. on 2 and 3 ranks the step runs on each rank's own spheres and ghosts (mod_ld_local, since
    2026-11-29: contacts, links, the 6N rows and the velocities of a rank's local set, its run log
    says so), which the agreement in 2. and 3. then checks: an own sphere that missed a contact,
    a link or a ghost's velocity would move at O(1) differently.
 6. the local sets are the state between steps, and the output takes each rank's own spheres of
    them (the series, the particle snapshots, the checkpoints with the springs gathered on rank
    0): with a snapshot every 8 steps, 3 ranks never gather the replicated state (0 times in 40
    steps, the run log says), their series agrees with 1 rank's at every step, the snapshots hold
    1 rank's spheres of their steps, and the final checkpoint 1 rank's (positions, velocities,
    omega, the Adams-Bashforth velocities, the springs' pairs and values); the restart in 3.
    starts from such a checkpoint. In between, the spheres that cross a slab face migrate with
    their velocities and Adams-Bashforth history, and the contacts' springs go to the ranks of the
    spheres they touch (more in test_ld_migration).
Tolerance: the CG iterations run to a relative residual of 1e-12; on more ranks their inner
products sum in another order, which changes the iterates at round-off and the converged solution
within the solver's tolerance. Measured (2026-11-28): at most 4.2e-13 (omega, the smallest
quantity), 1.9e-14 (velocity), 2.6e-16 (position). 1e-10 leaves a factor 250 and is far below what
this test guards against: a block row set by the wrong rank, lost or set twice, or a share of the
solution not gathered, which change the velocities at O(1)."""
import os
import re
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 13.78, 13.78, 13.78, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 10, particles_every = {every} /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5e-3, friction = 0.5 /
&rheology discard_strain = 0.02, average_strain = 0.06, blocks = 2 /
&run title = 'lubrication dynamics on several ranks' /
"""
# the motion, and what the statistics take from the step: each sphere's hydrodynamic stresslet (the
# links' corrections with the partners' velocities of the step) and contact stresslet (the implicit
# contacts' update, likewise)
QUANTITIES = ['particles/position', 'particles/velocity', 'particles/omega', 'particles/stresslet_hydro',
              'particles/stresslet_contact', 'particles/force_contact', 'particles/force_lubrication',
              'particles/torque_lubrication',
              # the statistics' samples, which the local step takes as each rank's shares summed
              # (mod_ld_local): stresses, pair counts in the shells, Q6, the smallest gap
              'core/stress_hydro', 'core/stress_contact', 'core/velocity_fit', 'pairs/shell', 'pairs/contact',
              'pairs/references', 'structure/q6', 'structure/q6_local', 'min_pair_gap']
TOL = 1e-10


def run(name, ranks, steps=40, args=(), d=None, every=0):
    d = d or T.scratch(name)
    deck = T.write_deck(d, 'd%d.nml' % steps, DECK.format(steps=steps, every=every))
    status, out, err = T.run(deck, d, np_ranks=ranks, args=list(args) + ['-particles_ksp_view'])
    return d, out


def results(d):
    s = T.series(os.path.join(d, 'out'))
    return {k: s[k] for k in QUANTITIES}


def compare(ref, other, what):
    for k in QUANTITIES:
        if ref[k].shape != other[k].shape:
            T.check(False, '%s: %s has shape %s, 1 rank %s' % (what, k, other[k].shape, ref[k].shape))
            continue
        scale = np.abs(ref[k]).max() or 1.0    # (a column of zeros: its absolute difference)
        diff = np.abs(other[k] - ref[k]).max() / scale
        T.check(diff <= TOL, '%s: %s max difference %.1e of its largest (%.3g) <= %.0e' % (what, k, diff, scale, TOL))


def links(out):
    m = re.search(r'lubrication: (\d+) pair links in the last step, at most (\d+) held on one rank', out)
    return (int(m.group(1)), int(m.group(2))) if m else (0, 0)


def matrix_type(out):
    m = re.search(r'type: (\w*baij)', out)
    return m.group(1) if m else None


d1, out1 = run('ld_ranks_1', 1)
solves = re.search(r'particle system with lubrication pairs: (\d+) sparse solves', out1)
T.check(solves is not None and int(solves.group(1)) == 40,
        'the sparse solve runs at every step (%s of 40)' % (solves.group(1) if solves else 'none'))
T.check(matrix_type(out1) == 'seqbaij', '1 rank: sequential matrix (%s)' % matrix_type(out1))
ref = results(d1)
total1, most1 = links(out1)
T.check(total1 > 0 and most1 == total1, '1 rank holds all %d pair links (%d)' % (total1, most1))
pairs1 = T.series(os.path.join(d1, 'out'))['lubrication_pairs']
dirs = {}
for n in (2, 3):
    d, out = run('ld_ranks_%d' % n, n)
    dirs[n] = d
    T.check(matrix_type(out) == 'mpibaij', '%d ranks: distributed matrix (%s)' % (n, matrix_type(out)))
    T.check("on the ranks' local sets" in out and "on the ranks' local sets" not in out1,
            '%d ranks: each rank steps its own spheres and ghosts (1 rank: every sphere)' % n)
    compare(ref, results(d), '%d ranks vs 1' % n)
    total, most = links(out)
    T.check(total == total1 and total / n <= most < total,
            '%d ranks: no rank holds all %d pair links (at most %d on one)' % (n, total, most))
    pairs = T.series(os.path.join(d, 'out'))['lubrication_pairs']
    T.check(np.array_equal(pairs, pairs1), '%d ranks: the series counts the pair links of the whole system '
            '(%d-%d, as 1 rank)' % (n, pairs.min(), pairs.max()))

# restart on another rank count: 20 steps on 2 ranks, then 20 on 3
d, _ = run('ld_ranks_restart', 2, steps=20)
T.check(int(T.h5_attr(os.path.join(d, 'out', 'checkpoint.h5'), 'step')[0]) == 20, 'checkpoint at step 20 (2 ranks)')
run('ld_ranks_restart', 3, steps=40, args=['-restart', 'out/checkpoint.h5'], d=d)
compare(ref, results(d), '20 steps on 2 ranks + restart + 20 on 3 vs 40 on 1')
# restart on as many ranks: the checkpoint keeps the sets the run held (particles/sets_made_z), so
# the restart has the same owners, ghosts and rows, and repeats the run's arithmetic bitwise
d, _ = run('ld_ranks_restart_same', 2, steps=20)
_, out_restart = run('ld_ranks_restart_same', 2, steps=40, args=['-restart', 'out/checkpoint.h5'], d=d)
# (the deck packs its spheres: a restart takes their count and radii, not a packing, whose
# positions the checkpoint replaces)
T.check('packing: not made at a restart: 250 spheres' in out_restart and 'smallest gap' not in out_restart,
        'the restart does not pack the spheres again (the run log)')
same, two = results(d), results(dirs[2])
worst = max(np.abs(same[k] - two[k]).max() for k in QUANTITIES)
T.check(worst == 0.0, '20 steps on 2 ranks + restart + 20 on 2 = 40 on 2 bitwise (largest difference %.1e)' % worst)

# the state carried on the local sets between the snapshots
d3, out3 = run('ld_ranks_every8_3', 3, every=8)
m = re.search(r'replicated particles of (\d+) spheres \(([\d.]+) kB a rank\) released at the first step; '
              r'each rank holds its own spheres and their ghosts only \(at the end at most (\d+) of the', out3)
T.check(m is not None and float(m.group(2)) > 0 and int(m.group(3)) < int(m.group(1)),
        '3 ranks, a snapshot every 8 steps: the replicated particles released at the first step, no rank '
        'holding every sphere (%s)' % (m.group(0) if m else 'no such log line'))
compare(ref, results(d3), '3 ranks vs 1, a snapshot every 8 steps')
worst = 0.0
for step in (8, 16, 24, 32, 40):
    snap = T.read_h5(os.path.join(d3, 'out', 'particles_%08d.h5' % step), ['particles/position'])['particles/position']
    worst = max(worst, np.abs(snap - ref['particles/position'][step - 1]).max() / np.abs(ref['particles/position']).max())
T.check(worst <= TOL, '3 ranks: the snapshots of steps 8-40 hold 1 rank\'s positions (%.1e of the largest)' % worst)
CHECKPOINT = ['particles/position', 'particles/velocity', 'particles/omega', 'particles/velocity_prev',
              'contacts/spring']
c1 = T.read_h5(os.path.join(d1, 'out', 'checkpoint.h5'), CHECKPOINT + ['contacts/ids'])
c3 = T.read_h5(os.path.join(d3, 'out', 'checkpoint.h5'), CHECKPOINT + ['contacts/ids'])
T.check(np.array_equal(c1['contacts/ids'], c3['contacts/ids']),
        '3 ranks: the final checkpoint holds 1 rank\'s %d springs\' pairs' % len(c1['contacts/ids']))
for k in CHECKPOINT:
    e = np.abs(c3[k] - c1[k]).max() / (np.abs(c1[k]).max() or 1.0) if c3[k].shape == c1[k].shape else np.inf
    T.check(e <= TOL, '3 ranks: the final checkpoint\'s %s is 1 rank\'s (%.1e of its largest)' % (k, e))
T.finish()
