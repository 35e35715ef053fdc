"""Invariant: the particle snapshots (particles_NNNNNNNN.h5) and the checkpoint's /particles, which
every rank writes together through parallel HDF5 since issue 45 (each rank the rows of the spheres
in its z-slab, mod_particles_io, mod_h5_parallel; doc/DESIGN.md "Files"), hold exactly the run's
state, in the layout one writer gave them, on any number of ranks:
 1. on 1, 2 and 3 ranks, each snapshot's position, velocity and omega and the checkpoint's
    position, velocity and omega are bitwise the series record of their step (series.h5 is written
    by every rank too, but each rank writes a contiguous range of spheres after an all-to-all,
    mod_series, not the rows of its slab: a row written by the wrong rank, lost or shifted in
    either shows here), and each snapshot's radius is the deck's;
 2. the files have the same datasets, shapes, types, chunks, Fletcher-32 filters (h5py verifies
    the checksum on every read) and attributes on every rank count as on 1 rank; the attributes'
    values are equal;
 3. where the state does not depend on the rank count (a DNS deck whose two spheres move with
    prescribed velocities: on 3 ranks the middle slab owns no sphere and takes part in the
    collective writes with an empty selection), every /particles dataset of the snapshots and of
    the checkpoint is bitwise 1 rank's; where it does (lubrication dynamics, whose CG sums its
    inner products in another order on more ranks), within 1e-10 of each quantity's largest (as
    tests/regression/test_ld_rank_independence.py);
 4. a restart on 1 rank from the checkpoint 3 ranks wrote (its checks: checksums, deck, particle
    count) continues as the uninterrupted 1-rank run does: the records after it within 1e-10
    (test_ld_rank_independence restarts from 2 ranks on 3);
 5. a collective write that fails (injected: a directory, not removable, where the .tmp must be
    created) stops every rank of a 3-rank run with status 3 and one message naming the file, and
    the last checkpoint stays whole: a snapshot (particles_00000010.h5.tmp), and a checkpoint of a
    run continued from a step-10 checkpoint (checkpoint.h5.tmp), which keeps step 10;
 6. series.h5, which every rank writes together since issue 45 (each rank buffers the per-sphere
    columns of its own spheres only; mod_series), has on 2 and 3 ranks 1 rank's layout (datasets,
    shapes, types, chunks, maximal shapes, filters, attributes), and its values agree with 1 rank's
    within 1e-12 of each quantity's scale (wall_time excepted): the ranks' runs differ only in the
    order of CG's reductions and of the links' sums (test_ld_rank_independence), whose round-off is
    relative to the largest term of a balance, so the scale of a force, torque or stresslet is the
    largest of its hydro, lubrication and contact parts (force_hydro, ~1e-10 here, is a sum of such
    terms that nearly cancel), of another dataset its own largest value (measured: 2e-14 at most,
    2026-11-29); in the DNS, whose spheres move as prescribed, their position, velocity and omega
    are bitwise 1 rank's;
 7. a collective write of the series that fails on every rank (injected with strace: the opening of
    series.parts/0000000021.h5.tmp fails with ENOSPC on each of 3 ranks, in the 3-rank run
    continued from its step-20 checkpoint) stops every rank with status 3 and one message naming
    the part, and the published series stays whole: series.h5 holds steps 1..20 once each, no part
    is left.
    (tests/regression/test_full_disk.py covers the full disk, which the free-space check before
    every parallel write catches.)
Decks: lubrication dynamics, 24 rough frictional spheres (phi 0.2) in a Lees-Edwards cube of 8 a,
30 steps (the 3-rank run 20, then its restart to 30 on 1 rank), snapshots every 10 steps; DNS, a
20 x 20 x 30-cell channel with walls, 10 steps, snapshots and checkpoints every 5. ~17 s on 2 cores.
Needs strace (scripts/install-deps) for 7."""
import os
import shutil
import subprocess
import h5py
import numpy as np
import fdsusp_testlib as T

LD = """&domain box = 8, 8, 8, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 10, series_every = 1, particles_every = 10, checkpoint_every = 10 /
&particles solid_fraction = 0.2, seed = 3 /
&contact roughness = 5e-3, friction = 0.5 /
"""
DNS = """&domain box = 8, 8, 12, cells_per_radius = 2.5, y_boundary = 'walls', shear_rate = 1 /
&lubrication model = 'simple' /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-2, steps = 10 /
&output directory = 'out', progress_every = 5, series_every = 1, particles_every = 5, checkpoint_every = 5 /
&particles number = 2, motion = 'prescribed', position(:,1) = 4.0, 3.0, 1.5, position(:,2) = 4.0, 5.0, 10.5,
           velocity(:,1) = 0.25, 0, 0.1, velocity(:,2) = -0.25, 0, -0.1,
           omega(:,1) = 0, 0, 0.5, omega(:,2) = 0, 0, -0.5 /
"""
STATE = ['position', 'velocity', 'omega']
TOL = 1e-10


def run(name, deck, ranks, args=(), d=None):
    d = d or T.scratch(name)
    T.run(T.write_deck(d, 'deck.nml', deck), d, np_ranks=ranks, args=list(args))
    return os.path.join(d, 'out')


def layout(path):
    """Every object under /particles: datasets as (shape, dtype, chunks, fletcher32, attributes),
    the group's attributes, and the values of every dataset."""
    shape, values = {}, {}
    with h5py.File(path, 'r') as f:
        g = f['particles']
        shape['@'] = {k: np.array(v).tolist() for k, v in g.attrs.items()}
        for name, d in g.items():
            shape[name] = (d.shape, str(d.dtype), d.chunks, d.fletcher32,
                           {k: np.array(v).tolist() for k, v in d.attrs.items()})
            values[name] = d[()]          # read whole: h5py verifies the Fletcher-32 checksum
    return shape, values


def files(out):
    names = sorted(f for f in os.listdir(out) if f.startswith('particles_') and f.endswith('.h5'))
    return names + ['checkpoint.h5']


def against_series(out, what, radii=None):
    """Check 1: the files' state is the series record of their step, bitwise."""
    s = T.series(out)
    steps = list(np.asarray(s['step']).astype(int))
    for name in files(out):
        path = os.path.join(out, name)
        step = int(T.h5_attr(path, 'step')[0]) if name == 'checkpoint.h5' else int(name[10:18])
        _, v = layout(path)
        k = steps.index(step)
        same = all(np.array_equal(v[q], s['particles/' + q][k]) for q in STATE)
        T.check(same, '%s: %s step %d: position, velocity, omega are bitwise the series record' % (what, name, step))
        if radii is not None and 'radius' in v:
            T.check(np.array_equal(v['radius'][:, 0], radii), '%s: %s radius is the deck\'s' % (what, name))


def against_one_rank(ref, out, what, tol):
    """Checks 2 and 3: same layout as 1 rank's, values bitwise (tol None) or within tol."""
    for name in files(ref):
        path = os.path.join(out, name)
        if not T.check(os.path.exists(path), '%s: %s written' % (what, name)):
            continue
        shape1, v1 = layout(os.path.join(ref, name))
        shape, v = layout(path)
        # the ranks' local sets, which a checkpoint of several ranks keeps for an exact restart on
        # as many (doc/DESIGN.md "Files"): one column per sphere, made for this rank count
        made = shape.pop('sets_made_z', None), shape['@'].pop('sets_made_ranks', None)
        v.pop('sets_made_z', None)
        if made[0] is not None:
            T.check(name == 'checkpoint.h5' and made[0][0] == (v1['position'].shape[0], 1) and made[1] is not None,
                    '%s: %s keeps the local sets (sets_made_z %s, made for %s ranks)' % (what, name, made[0][0], made[1]))
        T.check(shape == shape1, '%s: %s has 1 rank\'s datasets, shapes, chunks, Fletcher-32 and attributes'
                % (what, name))
        for q in sorted(v1):
            if q not in v or v[q].shape != v1[q].shape:
                continue
            if tol is None:
                T.check(np.array_equal(v[q], v1[q]), '%s: %s /particles/%s bitwise 1 rank\'s' % (what, name, q))
            else:
                scale = max(np.abs(v1[q]).max(), 1e-300)
                diff = np.abs(v[q] - v1[q]).max() / scale
                T.check(diff <= tol, '%s: %s /particles/%s within %.0e of 1 rank\'s (%.1e)' % (what, name, q, tol, diff))


def series_layout(out):
    """series.h5: {dataset: (shape, maxshape, dtype, chunks, compression, fletcher32, attributes)}
    and the root's attributes, and {dataset: values}."""
    shape, values = {}, {}
    with h5py.File(os.path.join(out, 'series.h5'), 'r') as f:
        shape['@'] = {k: np.array(v).tolist() for k, v in f.attrs.items()}

        def visit(name, d):
            if isinstance(d, h5py.Dataset):
                shape[name] = (d.shape, d.maxshape, str(d.dtype), d.chunks, d.compression, d.fletcher32,
                               {k: np.array(v).tolist() for k, v in d.attrs.items()})
                values[name] = d[()]
        f.visititems(visit)
    return shape, values


def series_scale(values, name):
    """Check 6's scale of a dataset: of particles/force_hydro etc. the largest of its parts."""
    family = name.rsplit('_', 1)[0] + '_' if name.startswith('particles/') and '_' in name else name
    return max(max(np.abs(v).max(initial=0.0) for q, v in values.items() if q == name or q.startswith(family)),
               1e-300)


def series_against_one_rank(ref, out, what, tol=1e-12, exact=()):
    """Check 6: out's series.h5 has ref's layout, values within tol of the scale (exact: bitwise)."""
    shape1, v1 = series_layout(ref)
    shape, v = series_layout(out)
    T.check(shape == shape1, '%s: series.h5 has 1 rank\'s datasets, shapes, types, chunks, filters and attributes'
            % what)
    worst, where = 0.0, ''
    for q in sorted(v1):
        if q == 'wall_time' or q not in v or v[q].shape != v1[q].shape or v1[q].size == 0:
            continue
        if q in exact:
            T.check(np.array_equal(v[q], v1[q]), '%s: series.h5 %s bitwise 1 rank\'s' % (what, q))
            continue
        diff = np.abs(np.asarray(v[q], float) - v1[q]).max() / series_scale(v1, q)
        if diff >= worst:
            worst, where = diff, q
    if exact:
        return
    T.check(worst <= tol, '%s: series.h5 within %.0e of 1 rank\'s (largest: %.1e, %s)' % (what, tol, worst, where))


# DNS, prescribed motion: bitwise on every rank count
dns = {n: run('pio_dns_%d' % n, DNS, n) for n in (1, 2, 3)}
for n in (1, 2, 3):
    against_series(dns[n], 'DNS %d rank(s)' % n, radii=np.ones(2))
for n in (2, 3):
    against_one_rank(dns[1], dns[n], 'DNS %d ranks' % n, None)
    series_against_one_rank(dns[1], dns[n], 'DNS %d ranks' % n,
                            exact=['particles/' + q for q in STATE])

# lubrication dynamics: 30 steps on 1 and 2 ranks, 20 on 3 and then 10 more on 1 from its checkpoint
ld1 = run('pio_ld_1', LD.format(steps=30), 1)
ld2 = run('pio_ld_2', LD.format(steps=30), 2)
ld3 = run('pio_ld_3', LD.format(steps=20), 3)
for out, what in ((ld1, 'LD 1 rank'), (ld2, 'LD 2 ranks'), (ld3, 'LD 3 ranks')):
    against_series(out, what, radii=np.ones(24))
against_one_rank(ld1, ld2, 'LD 2 ranks', TOL)
ld1_20 = run('pio_ld_1_at_20', LD.format(steps=20), 1)
against_one_rank(ld1_20, ld3, 'LD 3 ranks', TOL)
series_against_one_rank(ld1, ld2, 'LD 2 ranks')
series_against_one_rank(ld1_20, ld3, 'LD 3 ranks')

# restart on 1 rank from the 3 ranks' checkpoint (step 20); check 7 continues a copy on 3 ranks
d3 = os.path.dirname(ld3)
d7 = T.scratch('pio_fail_series')
shutil.rmtree(d7)
shutil.copytree(d3, d7)
T.check(int(T.h5_attr(os.path.join(ld3, 'checkpoint.h5'), 'step')[0]) == 20, 'LD 3 ranks: checkpoint at step 20')
run('pio_ld_3', LD.format(steps=30), 1, args=['-restart', 'out/checkpoint.h5'], d=d3)
s1, s = T.series(ld1), T.series(ld3)
T.check(np.array_equal(np.asarray(s['step']), np.asarray(s1['step'])), 'restart: the series holds steps 1..30 once each')
after = np.asarray(s1['step']) > 20
T.check(after.sum() == 10, 'restart: 10 records after the checkpoint')
for q in STATE:
    a, b = s1['particles/' + q][after], s['particles/' + q][after]
    diff = np.abs(b - a).max() / np.abs(a).max()
    T.check(diff <= TOL, 'restart on 1 rank from 3 ranks\' checkpoint: particles/%s of steps 21-30 within %.0e of '
            'the uninterrupted run (%.1e)' % (q, TOL, diff))
against_series(ld3, 'LD 3 ranks + restart on 1')


def failing(name, blocker, deck, args=(), before=None):
    """Run deck on 3 ranks with out/BLOCKER a directory holding a file; (status, stderr, out)."""
    d = T.scratch(name)
    out = os.path.join(d, 'out')
    deck_path = T.write_deck(d, 'deck.nml', deck)
    if before:
        T.run(T.write_deck(d, 'before.nml', before), d, np_ranks=3)
    os.makedirs(os.path.join(out, blocker, 'x'))
    status, _, err = T.run(deck_path, d, np_ranks=3, args=list(args), expect_ok=False, timeout=120)
    return status, err, out


status, err, out = failing('pio_fail_snapshot', 'particles_00000010.h5.tmp', LD.format(steps=20))
T.check(status == 3 and 'fdsusp: fatal: out/particles_00000010.h5 cannot be created' in err,
        'snapshot write fails on 3 ranks: status %d, the message names the file' % status)
T.check(int(T.h5_attr(os.path.join(out, 'checkpoint.h5'), 'step')[0]) == 0, 'snapshot write fails: the last '
        'checkpoint (step 0) is whole')
status, err, out = failing('pio_fail_checkpoint', 'checkpoint.h5.tmp', LD.format(steps=20),
                           ['-restart', 'out/checkpoint.h5'], before=LD.format(steps=10))
T.check(status == 3 and 'fdsusp: fatal: out/checkpoint.h5.tmp cannot be created' in err and
        'out/checkpoint.h5, is kept' in err, 'checkpoint write fails on 3 ranks: status %d, the message names '
        'the file and keeps the last checkpoint' % status)
T.check(int(T.h5_attr(os.path.join(out, 'checkpoint.h5'), 'step')[0]) == 10, 'checkpoint write fails: the last '
        'checkpoint (step 10) is whole')

# 7. the series' part cannot be created on any of 3 ranks (strace fails its opening with ENOSPC), in
# the 3-rank run continued from its step-20 checkpoint to 30 (a copy of it, made before the restart)
part = 'out/series.parts/0000000021.h5.tmp'
cmd = T.command(T.write_deck(d7, 'deck.nml', LD.format(steps=30)), 3, ['-restart', 'out/checkpoint.h5'])
at = cmd.index(T.FDSUSP)
cmd[at:at] = ['strace', '-f', '-o', '/dev/null', '-P', part, '-e', 'trace=openat', '-e', 'inject=openat:error=ENOSPC']
p = subprocess.run(cmd, cwd=d7, env=T.ENV, capture_output=True, text=True, timeout=120)
fatal = [l for l in p.stderr.splitlines() if l.startswith('fdsusp: fatal:')]
T.check(p.returncode == 3 and len(fatal) == 1 and fatal[0].startswith('fdsusp: fatal: ' + part + ' cannot be created'),
        'a series part cannot be created on 3 ranks: status %d, one message naming it: %s'
        % (p.returncode, fatal or p.stderr[-300:]))
steps = T.series(os.path.join(d7, 'out'))['step']
T.check(np.array_equal(steps, np.arange(1, 21)) and not os.listdir(os.path.join(d7, 'out', 'series.parts')),
        'a series part cannot be created: series.h5 keeps steps 1..20 once each, no part is left')
T.finish()
