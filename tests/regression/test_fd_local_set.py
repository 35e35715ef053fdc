"""Invariant: the resolved step (fluid and fictitious domain) gives the same suspension on any number
of ranks when each rank steps only its own spheres and their ghosts (mod_ld_local for the DNS,
since 2026-11-29: the slabs are the grid's z-ranges; geometry, moments and the update on a rank's
faces for its local set, each sphere's parts added into its owner's through the halo, the owner
alone solving its rows; contacts, links and statistics on the local set). Scene: rough frictional
spheres (roughness 0.03 a, so that contacts with friction springs open and close) with full
lubrication at phi 0.3 in a walled Couette cell 8 x 8 x 8 a (a/Delta = 4, 32^3
cells), driven along z too by a body force so that spheres cross the slab faces and the sets are
made again during the run; and the same in a Lees-Edwards cube, where the images across y = 0, Ly
are visited too.
 1. on 2 and 3 ranks (unequal slabs on 3: 16, 8, 8 planes) the run log says each rank steps its
    own spheres and ghosts, the replicated state is never gathered (0 times), and the sets are made
    again at least once after the first (spheres moved half the skin along z);
 2. 2 and 3 ranks agree with 1 rank at every step: positions, velocities, angular velocities,
    hydrodynamic and contact stresslets, contact and lubrication forces, the core stresses of the
    statistics; and in the final checkpoint u, v, w, p, Lambda, the spheres' state and the
    contacts' springs (the same pairs);
 3. 2 ranks on local sets agree with 2 ranks on the replicated state (-fd_local_set 0, the path
    before 2026-11-29);
 4. 20 steps on 2 ranks, a checkpoint, 20 more on 3 agree with 40 on 1 rank; 20 more on 2 ranks
    equal 40 on 2 bitwise (the checkpoint keeps the sets the run held: particles/sets_made_z);
 5. the Lees-Edwards cube: 2 and 3 ranks agree with 1 rank at every step (2.'s quantities);
 6. stress control (the mean shear stress 3, 20 steps), between walls and in the Lees-Edwards
    cube: 2 and 3 ranks give 1 rank's rate and spheres at every step.
Tolerance: the moments of a sphere whose faces lie on two ranks are summed in another order, and
the particle solve (CG to a relative residual of 1e-12 when lubrication couples the spheres) sums
its inner products in another order; the spheres carry such differences on through contacts and
lubrication. Measured (2026-11-29): at most 1.1e-12 (the contact stresses, Lees-Edwards on 3
ranks; 2.7e-13 between walls); TOL = 1e-10 of each quantity's largest
magnitude is far below what this test guards against: a moment, a face or a ghost's velocity
missing on one rank, or a sphere's parts summed twice, change the motion at O(1e-3) or more
(without the ghosts' parts added into their owners, velocities differ by O(1))."""
import os
import re
import h5py
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 8, 8, 8, cells_per_radius = 4, y_boundary = '{boundary}', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', body_force = 0, 0, {force}{fluid} /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 10 /
&particles solid_fraction = 0.3, seed = 3 /
&contact roughness = 3e-2, friction = 0.5 /
&lubrication model = 'full' /
&rheology discard_strain = 0.0, average_strain = 0.08, blocks = 2 /
"""
QUANTITIES = ['particles/position', 'particles/velocity', 'particles/omega', 'particles/stresslet_hydro',
              'particles/stresslet_contact', 'particles/force_contact', 'particles/force_lubrication',
              'core/stress_hydro', 'core/stress_contact', 'core/flow_fit']
FIELDS = ['u', 'v', 'w', 'p', 'lambda_u', 'lambda_v', 'lambda_w', 'particles/position', 'particles/velocity',
          'particles/omega', 'particles/velocity_prev', 'contacts/spring']
CHECKPOINT = ['checkpoint:' + k for k in FIELDS]
TOL = 1e-10


def run(name, ranks, steps=40, args=(), d=None, boundary='walls', force=1.5, shear='', fluid=''):
    d = d or T.scratch(name)
    deck = T.write_deck(d, 'd%d.nml' % steps, DECK.format(steps=steps, boundary=boundary, force=force, fluid=fluid)
                        + shear)
    status, out, err = T.run(deck, d, np_ranks=ranks, args=list(args))
    return d, out


def results(d, fields=True):
    s = T.series(os.path.join(d, 'out'))
    r = {k: s[k] for k in QUANTITIES}
    if fields:
        path = os.path.join(d, 'out', 'checkpoint.h5')
        # (the checkpoint's datasets under 'checkpoint:', apart from the series' of the same name)
        for k, v in T.read_h5(path, [k for k in FIELDS if not k.startswith('contacts/')]).items():
            r['checkpoint:' + k] = v
        with h5py.File(path, 'r') as f:
            n = int(f['contacts'].attrs['count'][0])
            r['checkpoint:contacts/ids'] = np.array(f['contacts/ids']) if n else np.zeros((0, 2), int)
            r['checkpoint:contacts/spring'] = np.array(f['contacts/spring']) if n else np.zeros((0, 3))
    return r


def compare(ref, other, what, keys):
    worst = {}
    for k in keys:
        if ref[k].shape != other[k].shape:
            T.check(False, '%s: %s has shape %s, 1 rank %s' % (what, k, other[k].shape, ref[k].shape))
            continue
        scale = (np.abs(ref[k]).max() if ref[k].size else 0.0) or 1.0
        worst[k] = ((np.abs(other[k] - ref[k]).max() if ref[k].size else 0.0) / scale, scale)
    bad = {k: v for k, v in worst.items() if v[0] > TOL}
    T.check(not bad and len(worst) == len(keys), '%s: every quantity within %.0e of its largest (worst: %s)'
            % (what, TOL, ', '.join('%s %.1e' % (k.split('/')[-1], v[0]) for k, v in
                                    sorted(worst.items(), key=lambda kv: -kv[1][0])[:4])))
    for k, v in bad.items():
        print('    %s: %.2e of its largest (%.3g)' % (k, v[0], v[1]))


def log_counts(out):
    # (released: the replicated particles' kB freed at the first step)
    released = re.search(r'replicated particles of (\d+) spheres \(([\d.]+) kB a rank\) released at the first '
                         r'step; each rank holds its own spheres and their ghosts only', out)
    made = re.search(r'the sets made (\d+) times in (\d+) steps', out)
    return (float(released.group(2)) if released else None, int(made.group(1)) if made else None)


d1, out1 = run('fd_local_1', 1)
ref = results(d1)
T.check("on the ranks' local sets" not in out1, '1 rank: the replicated step')
moved = np.abs(ref['particles/position'][-1, :, 2] - ref['particles/position'][0, :, 2]).max()
T.check(moved > 0.15, 'spheres drift along z (largest %.2f a in 40 steps)' % moved)
contacts = T.series(os.path.join(d1, 'out'))['contacts_pair']
T.check(np.count_nonzero(contacts) >= 10 and len(ref['checkpoint:contacts/ids']) > 0,
        'contacts at %d of 40 steps (up to %d pairs), %d springs in the final checkpoint'
        % (np.count_nonzero(contacts), contacts.max(), len(ref['checkpoint:contacts/ids'])))
for n in (2, 3):
    d, out = run('fd_local_%d' % n, n)
    # (40 doubles a sphere: 37 x 40 x 8 B = 11.6 kB)
    released, made = log_counts(out)
    T.check("spheres on the ranks' local sets" in out and released is not None and released >= 11.5
            and made is not None and made >= 2, '%d ranks: local sets, the replicated particles released (%s kB '
            'a rank), the sets made %s times in 40 steps' % (n, released, made))
    other = results(d)
    if n == 2:
        two = other
    compare(ref, other, '%d ranks vs 1' % n, QUANTITIES + CHECKPOINT)
    T.check(np.array_equal(ref['checkpoint:contacts/ids'], other['checkpoint:contacts/ids']),
            '%d ranks: the final checkpoint holds 1 rank\'s %d springs\' pairs' % (n, len(ref['checkpoint:contacts/ids'])))
    if n == 2:
        dr, outr = run('fd_local_2_replicated', 2, args=['-fd_local_set', '0'])
        T.check("on the ranks' local sets" not in outr, '-fd_local_set 0: the replicated step')
        compare(results(dr), other, '2 ranks: local sets vs replicated', QUANTITIES + CHECKPOINT)

# restart across rank counts from a checkpoint written from the ranks' shares
d, _ = run('fd_local_restart', 2, steps=20)
T.check(int(T.h5_attr(os.path.join(d, 'out', 'checkpoint.h5'), 'step')[0]) == 20, 'checkpoint at step 20 (2 ranks)')
run('fd_local_restart', 3, steps=40, args=['-restart', 'out/checkpoint.h5'], d=d)
compare(ref, results(d), '20 steps on 2 ranks + restart + 20 on 3 vs 40 on 1', QUANTITIES + CHECKPOINT)

# restart on as many ranks: the checkpoint keeps each sphere's z when the sets were made
# (particles/sets_made_z), so the restart holds the run's own sets (owners, ghosts, rows) and
# repeats its arithmetic bitwise (made from the positions instead, a sphere that crossed a slab
# face since the sets were made changes owner, and its sums their order: test_contact_restart and
# test_batch_chain failed so, by 8e-16 in the velocities)
d, _ = run('fd_local_restart_same', 2, steps=20)
path = os.path.join(d, 'out', 'checkpoint.h5')
with h5py.File(path, 'r') as f:
    T.check('particles/sets_made_z' in f and int(f['particles'].attrs['sets_made_ranks'][0]) == 2,
            'the checkpoint of 2 ranks keeps the sets (particles/sets_made_z, made for 2 ranks)')
run('fd_local_restart_same', 2, steps=40, args=['-restart', 'out/checkpoint.h5'], d=d)
same = results(d)
worst = max(np.abs(same[k] - two[k]).max() for k in QUANTITIES + CHECKPOINT if two[k].size)
T.check(worst == 0.0, '20 steps on 2 ranks + restart + 20 on 2 = 40 on 2 bitwise (largest difference %.1e)' % worst)

# Lees-Edwards: the images across y = 0, Ly on the local sets
dl1, _ = run('fd_local_le_1', 1, boundary='lees-edwards', steps=30)
le_ref = results(dl1, fields=False)
for n in (2, 3):
    d, out = run('fd_local_le_%d' % n, n, boundary='lees-edwards', steps=30)
    T.check("spheres on the ranks' local sets" in out, '%d ranks, Lees-Edwards: local sets' % n)
    compare(le_ref, results(d, fields=False), 'Lees-Edwards, %d ranks vs 1' % n, QUANTITIES)
# stress control (doc/METHOD.md §7.4): both solves on the local sets, the walls' forces and the
# spheres' stresslets summed over the own spheres of every rank, the rate the same
for boundary in ('walls', 'lees-edwards'):
    refs = None
    for n in (1, 2, 3):
        d, out = run('fd_local_stress_%s_%d' % (boundary, n), n, boundary=boundary, steps=20,
                     shear="&shear control = 'stress', stress = 3.0 /", fluid=', viscous_theta = 1')
        r = results(d, fields=False)
        r['shear/rate'] = T.series(os.path.join(d, 'out'))['shear/rate']
        if refs is None:
            refs = r
            T.check(np.abs(r['shear/rate'] - 1.0).max() > 1e-3, 'stress control, %s: the rate is set by the stress '
                    '(%.3f-%.3f)' % (boundary, r['shear/rate'].min(), r['shear/rate'].max()))
            continue
        T.check("spheres on the ranks' local sets" in out, 'stress control, %s, %d ranks: local sets' % (boundary, n))
        compare(refs, r, 'stress control, %s, %d ranks vs 1' % (boundary, n), QUANTITIES + ['shear/rate'])
T.finish()
