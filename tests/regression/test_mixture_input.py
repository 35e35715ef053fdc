"""Invariant: spheres of several sizes are read as the deck and the position file state them, and
what does not add up is refused before any work with one message naming the file, the group and
the variable (or the file's dataset) (doc/INPUT.md "Mixtures"). &particles radius lists the
species, smallest first, the smallest 1 (the unit of length) for a mixture; volume_share or
number_share (one of them, one positive share per species, summing to 1 within 1e-9) gives the
composition of a packing; a position file's particles/radius (N, any shape holding N numbers)
must hold only the deck's radii and each of them. Equal spheres are unchanged: a deck of one
radius with a position file whose particles/radius is that radius runs, and its particle
snapshot holds each sphere's radius. Lubrication dynamics moves a mixture (it runs, and its
snapshot holds each sphere's radius as the file gave it), also a mixture packed at start-up
(solid_fraction: its snapshot holds the species' radii in the counts the log gives, their volume
within half a large sphere of the asked fraction); so does the resolved fluid, from a file and
from inline particles with &particles species(i) (each one of the radii, every species present,
none beyond number). The full lubrication model of a mixture in the resolved fluid (doc/LUBRICATION.md
"Tables for mixtures") needs a table per species at its own resolution and one per unequal pair:
one missing, one of another cells_per_radius or size_ratio, an explicit &lubrication table, and
model 'simple' are each refused before any step with one message naming &lubrication and the
file (or variable); with its tables (synthetic, in the scratch directory through
$FDSUSP_TABLE_DIR) it runs and lubricates its unequal pair; a size ratio of 2/1.4 takes the table
calibrated at 1.428571 (the 6 decimals of the names). Exact checks (messages, status,
absence of any step) except the packed volume fraction (counts rounded per species)."""
import os
import fdsusp_testlib as T

LD = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 0.002, steps = 2 /
&output directory = 'out', progress_every = 1, particles_every = 2 /
&particles {particles} /
"""
# three spheres well apart: two of radius 1, one of 1.4
POSITIONS = [[2.0, 4.0, 4.0], [5.0, 4.0, 4.0], [2.0, 4.0, 1.5]]


def position_file(d, name, radii=None, shape=None):
    with T.h5py.File(os.path.join(d, name), 'w') as f:
        f.create_dataset('particles/position', data=T.np.array(POSITIONS))
        if radii is not None:
            r = T.np.array(radii, dtype=float)
            f.create_dataset('particles/radius', data=r.reshape(shape) if shape else r)


def refused(cases):
    """Each case (name, &particles text, words) in a directory of its own under d (the deck and
    copies of the position files), the runs four at a time (a refused run spends its time on MPI
    start-up): refused, one message naming the words, no step."""
    runs = []
    for k, (name, particles, words) in enumerate(cases):
        where = os.path.join(d, 'refused_%d' % k)
        os.makedirs(where)
        for f in FILES:
            T.shutil.copy(os.path.join(d, f), where)
        T.write_deck(where, 'mix.nml', LD.format(particles=particles))
        runs.append(dict(deck='mix.nml', cwd=where, expect_ok=False))
    for (name, particles, words), (status, out, err) in zip(cases, T.run_many(runs, cores=4)):
        messages = [line for line in err.splitlines() if line.startswith('fdsusp:') and 'warning' not in line]
        T.check(status == 2 and len(messages) == 1 and all(w in messages[0] for w in words),
                '%s: refused (status %d) with one message naming %s: %s' % (name, status, ', '.join(words), messages[:1]))
        T.check(not any(line.startswith('step ') for line in out.splitlines()), '%s: no step taken' % name)


d = T.scratch('mixture_input')
position_file(d, 'mixture.h5', [1.0, 1.0, 1.4])
position_file(d, 'mixture_2d.h5', [1.0, 1.0, 1.4], shape=(1, 3))     # as Fortran writes a list
position_file(d, 'foreign.h5', [1.0, 1.0, 1.3])
position_file(d, 'one_species.h5', [1.0, 1.0, 1.0])
position_file(d, 'no_radius.h5')
position_file(d, 'short_radius.h5', [1.0, 1.4])
FILES = ('mixture.h5', 'mixture_2d.h5', 'foreign.h5', 'one_species.h5', 'no_radius.h5', 'short_radius.h5')

MIX = "radius = 1.0, 1.4, volume_share = 0.5, 0.5, position_file = '{f}'"
refused([
    ('shares that do not sum to 1', "radius = 1.0, 1.4, volume_share = 0.5, 0.4, solid_fraction = 0.1",
     ['mix.nml', '&particles', 'variable volume_share', 'sums to']),
    ('both shares', "radius = 1.0, 1.4, volume_share = 0.5, 0.5, number_share = 0.5, 0.5, solid_fraction = 0.1",
     ['&particles', 'variable volume_share', 'one of them']),
    ('no shares', "radius = 1.0, 1.4, solid_fraction = 0.1", ['&particles', 'variable volume_share']),
    ('a share per species', "radius = 1.0, 1.4, number_share = 1.0, solid_fraction = 0.1",
     ['&particles', 'variable number_share', 'one positive share per species']),
    ('smallest radius not 1', "radius = 1.2, 1.4, volume_share = 0.5, 0.5, solid_fraction = 0.1",
     ['&particles', 'variable radius(1)', 'unit of length']),
    ('radii not increasing', "radius = 1.0, 0.8, volume_share = 0.5, 0.5, solid_fraction = 0.1",
     ['&particles', 'variable radius(2)', 'smallest first']),
    ('a gap in the list', "radius(1) = 1.0, radius(3) = 1.4, volume_share = 0.5, 0.5, solid_fraction = 0.1",
     ['&particles', 'variable radius', 'one after the other']),
    ('shares for one species', "radius = 1.0, volume_share = 0.5, 0.5, solid_fraction = 0.1",
     ['&particles', 'variable volume_share', 'radius lists one']),
    ('inline particles of a mixture without species', "radius = 1.0, 1.4, number = 1, position(:,1) = 4, 4, 4",
     ['&particles', 'variable species', 'no inline particle of species 2']),
    ('an inline species beyond the radii', "radius = 1.0, 1.4, number = 2, position(:,1) = 2, 4, 4, "
     "position(:,2) = 6, 4, 4, species = 1, 3", ['&particles', 'variable species(2)']),
    ('a species for a particle beyond number', "radius = 1.0, 1.4, number = 1, position(:,1) = 2, 4, 4, "
     "species = 1, 2", ['&particles', 'variable species(2)', 'beyond number']),
    ('file radius not the deck\'s', MIX.format(f='foreign.h5'), ['foreign.h5', 'particles/radius', 'sphere 3']),
    ('file lacks a species', MIX.format(f='one_species.h5'), ['one_species.h5', 'particles/radius', 'holds no sphere']),
    ('file without radii for a mixture', MIX.format(f='no_radius.h5'), ['no_radius.h5', 'particles/radius', 'missing']),
    ('file radii of another count', MIX.format(f='short_radius.h5'), ['short_radius.h5', 'particles/radius',
                                                                      'one radius per sphere']),
    ('file radii of one size, deck another', "radius = 1.4, position_file = 'one_species.h5'",
     ['one_species.h5', 'particles/radius', 'not one of the deck']),
])

# the resolved fluid moves a mixture (the fictitious domain takes each sphere's radius), from a
# position file and inline (species), here without lubrication correction
RESOLVED = LD.replace("&fluid model = 'none' /", "&fluid reynolds = 0.1 /\n&lubrication model = 'none' /").replace(
    "y_boundary = 'lees-edwards', shear_rate = 1", "cells_per_radius = 3")
out_dir = os.path.join(d, 'out')
INLINE = ("radius = 1.0, 1.4, number = 3, species = 1, 1, 2, " +
          ", ".join("position(:,%d) = %g, %g, %g" % ((i + 1,) + tuple(x)) for i, x in enumerate(POSITIONS)))
for name, particles in (('a position file', MIX.format(f='mixture.h5')), ('inline species', INLINE)):
    if os.path.isdir(out_dir):
        T.shutil.rmtree(out_dir)
    T.write_deck(d, 'resolved.nml', RESOLVED.format(particles=particles))
    status, out, err = T.run('resolved.nml', d, expect_ok=False)
    T.check(status == 0 and 'finished at step 2' in out, 'the resolved fluid moves a mixture from %s (status %d)'
            % (name, status))
    with T.h5py.File(os.path.join(out_dir, 'particles_00000002.h5'), 'r') as f:
        T.check(T.np.array_equal(T.np.ravel(f['particles/radius'][()]), [1.0, 1.0, 1.4]),
                'resolved fluid, %s: the particle snapshot holds each sphere\'s radius' % name)

# the full lubrication model of a mixture in the resolved fluid (doc/LUBRICATION.md "Tables for
# mixtures"): one table per species at its own resolution (radii 1, 1.4 at a/Delta = 4:
# resolved_a4.h5, resolved_a5.6.h5) and one per unequal pair (resolved_a4_ratio1.4.h5), looked for
# in $FDSUSP_TABLE_DIR here. Synthetic tables in the scratch directory (never in input/): the
# a/Delta = 4 table, a copy of it labelled 5.6, and the unequal pair's table made from it at
# lambda = 1 (sphere 2's columns exchange signs times sphere 1's, M already folded).
tables = os.path.join(d, 'tables')
os.makedirs(tables)
EXCHANGE = T.np.array([1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1] * 2, dtype=float)


def equal_table(name, cells_per_radius):
    T.shutil.copy(os.path.join(T.ROOT, 'input', 'lubrication', 'resolved_a4.h5'), os.path.join(tables, name))
    with T.h5py.File(os.path.join(tables, name), 'r+') as f:
        f.attrs['cells_per_radius'] = cells_per_radius


def unequal_table(name, size_ratio=1.4, cells_per_radius=4.0):
    with T.h5py.File(os.path.join(T.ROOT, 'input', 'lubrication', 'resolved_a4.h5'), 'r') as f:
        pair, scatter = f['pair/resolved'][()], f['pair/scatter'][()]
    with T.h5py.File(os.path.join(tables, name), 'w') as f:
        for key, rows in (('resolved', pair), ('scatter', scatter)):
            f.create_dataset('pair/' + key, data=T.np.hstack([rows, EXCHANGE * rows[:, 1:]]))
        f.attrs.update(cells_per_radius=cells_per_radius, size_ratio=size_ratio, radius_offset=0.38,
                       slip_kappa=0.5, command='tests/regression/test_mixture_input.py (synthetic)')


FULL = LD.replace("&fluid model = 'none' /", "&fluid reynolds = 0.1 /\n&lubrication {lub} /").replace(
    "y_boundary = 'lees-edwards', shear_rate = 1", "cells_per_radius = 4").replace(
    'box = 8.0, 8.0, 8.0', 'box = 10.0, 10.0, 10.0')
T.ENV['FDSUSP_TABLE_DIR'] = tables


def full_run(lub="model = 'full'"):
    if os.path.isdir(out_dir):
        T.shutil.rmtree(out_dir)
    T.write_deck(d, 'full.nml', FULL.format(lub=lub, particles=MIX.format(f='mixture.h5')))
    return T.run('full.nml', d, expect_ok=False)


def full_refused(name, words, lub="model = 'full'"):
    status, out, err = full_run(lub)
    messages = [line for line in err.splitlines() if line.startswith('fdsusp:') and 'warning' not in line]
    T.check(status == 2 and len(messages) == 1 and all(w in messages[0] for w in words),
            'full model of a mixture, %s: refused (status %d) with one message naming %s: %s'
            % (name, status, ', '.join(words), messages[:1]))
    T.check(not any(line.startswith('step ') for line in out.splitlines()), 'full model, %s: no step taken' % name)


equal_table('resolved_a4.h5', 4)
equal_table('resolved_a5.6.h5', 5.6)
full_refused('the unequal pair\'s table missing', ['full.nml', '&lubrication', 'variable model', '&particles radius',
             os.path.join(tables, 'resolved_a4_ratio1.4.h5'), 'is missing', 'scripts/calibrate.py 4 --size-ratio 1.4'])
unequal_table('resolved_a4_ratio1.4.h5')
os.remove(os.path.join(tables, 'resolved_a5.6.h5'))
full_refused('the larger species\' table missing', ['&lubrication', 'variable model',
             os.path.join(tables, 'resolved_a5.6.h5'), 'is missing', 'make calibrate CELLS_PER_RADIUS=5.6'])
equal_table('resolved_a5.6.h5', 4)
full_refused('a species\' table of another resolution', ['&lubrication', 'variable model', 'resolved_a5.6.h5',
             'cells_per_radius = 4', 'needs 5.6'])
equal_table('resolved_a5.6.h5', 5.6)
unequal_table('resolved_a4_ratio1.4.h5', size_ratio=2.0)
full_refused('an unequal table of another size ratio', ['&lubrication', 'variable model', 'resolved_a4_ratio1.4.h5',
             'size_ratio = 2', 'needs 1.4'])
unequal_table('resolved_a4_ratio1.4.h5')
full_refused('an explicit table', ['&lubrication', 'variable table', 'for equal spheres'],
             lub="model = 'full', table = '%s'" % os.path.join(tables, 'resolved_a4.h5'))
full_refused('model simple', ['&lubrication', 'variable model', 'simple', 'equal spheres'], lub="model = 'simple'")
# with its three tables the mixture runs, its unequal pair (spheres 1 and 3, xi = 0.083) lubricated
status, out, err = full_run()
logged = [line.split(': ', 1)[-1] for line in out.splitlines() if line.startswith('lubrication table: ')]
T.check(status == 0 and 'finished at step 2' in out and sorted(os.path.basename(p) for p in logged) ==
        ['resolved_a4.h5', 'resolved_a4_ratio1.4.h5', 'resolved_a5.6.h5'],
        'full model of a mixture with its three tables runs (status %d; tables %s)' % (status, logged))
if status == 0:
    s = T.series(out_dir)
    T.check(int(T.np.max(s['lubrication_pairs'])) == 1, 'full model of a mixture: the unequal pair is lubricated '
            '(%d links)' % int(T.np.max(s['lubrication_pairs'])))
# three species (radii 1, 1.4, 2 at a/Delta = 4): six tables, the pair (1.4, 2) at a/Delta 5.6 and
# size ratio 2/1.4, which the names and the table write to 6 decimals (1.428571): that table is
# accepted, and the last one read (resolved_a8.h5, made wrong here) is the one refused
with T.h5py.File(os.path.join(d, 'three.h5'), 'w') as f:
    f.create_dataset('particles/position', data=T.np.array([[2.5, 5.0, 5.0], [6.0, 5.0, 5.0], [4.0, 5.0, 9.5]]))
    f.create_dataset('particles/radius', data=T.np.array([1.0, 1.4, 2.0]))
unequal_table('resolved_a4_ratio2.h5', size_ratio=2.0)
unequal_table('resolved_a5.6_ratio1.428571.h5', size_ratio=1.428571, cells_per_radius=5.6)
equal_table('resolved_a8.h5', 4)
T.write_deck(d, 'three.nml', FULL.format(lub="model = 'full'", particles="radius = 1.0, 1.4, 2.0, position_file = 'three.h5'"))
status, out, err = T.run('three.nml', d, expect_ok=False)
messages = [line for line in err.splitlines() if line.startswith('fdsusp:') and 'warning' not in line]
T.check(status == 2 and len(messages) == 1 and 'resolved_a8.h5' in messages[0] and 'needs 8' in messages[0] and
        'resolved_a5.6_ratio1.428571.h5' in out,
        'three species: the table of size ratio 1.428571 for 2/1.4 accepted, the wrong resolved_a8.h5 refused: %s'
        % messages[:1])
del T.ENV['FDSUSP_TABLE_DIR']

# lubrication dynamics moves a mixture, its radii as the file gives them (N or 1 x N)
for name in ('mixture.h5', 'mixture_2d.h5'):
    if os.path.isdir(out_dir):
        T.shutil.rmtree(out_dir)
    # a box of 10: the lubrication search reaches (a_i + a_j)(1 + outer_cutoff/2) + skin = 4.2a + skin
    T.write_deck(d, 'ld_mix.nml', LD.replace('box = 8.0, 8.0, 8.0', 'box = 10.0, 10.0, 10.0')
                 .format(particles=MIX.format(f=name)))
    status, out, err = T.run('ld_mix.nml', d, expect_ok=False)
    T.check(status == 0 and 'finished at step 2' in out, 'lubrication dynamics runs the mixture of %s (status %d)'
            % (name, status))
    with T.h5py.File(os.path.join(out_dir, 'particles_00000002.h5'), 'r') as f:
        T.check(T.np.array_equal(T.np.ravel(f['particles/radius'][()]), [1.0, 1.0, 1.4]),
                '%s: the particle snapshot holds each sphere\'s radius' % name)

# lubrication dynamics packs a mixture at start-up (50/50 by volume, phi 0.2) and moves it
if os.path.isdir(out_dir):
    T.shutil.rmtree(out_dir)
T.write_deck(d, 'ld_packed.nml', LD.replace('box = 8.0, 8.0, 8.0', 'box = 10.0, 10.0, 10.0').format(
    particles='radius = 1.0, 1.4, volume_share = 0.5, 0.5, solid_fraction = 0.2'))
status, out, err = T.run('ld_packed.nml', d, expect_ok=False)
counts = [line for line in out.splitlines() if line.startswith('packing: spheres per species')]
T.check(status == 0 and 'finished at step 2' in out and len(counts) == 1,
        'lubrication dynamics packs a 1:1.4 mixture at start-up and moves it (status %d; %s)' % (status, counts))
with T.h5py.File(os.path.join(out_dir, 'particles_00000002.h5'), 'r') as f:
    radii = T.np.ravel(f['particles/radius'][()])
n_small, n_large = [int(v) for v in counts[0].split(':')[-1].split(',')] if counts else (-1, -1)
T.check(sorted(set(radii)) == [1.0, 1.4] and (radii == 1.0).sum() == n_small and (radii == 1.4).sum() == n_large,
        'packed mixture: the snapshot holds %d spheres of radius 1 and %d of 1.4, as the log says' % (n_small, n_large))
phi = (4 / 3 * T.np.pi * radii**3).sum() / 1000.0
T.check(abs(phi - 0.2) <= 0.5 * 4 / 3 * T.np.pi * 1.4**3 / 1000.0 * 2,
        'packed mixture: volume fraction %.4f within one sphere of each species of 0.2 (rounding per species)' % phi)

# equal spheres: a position file with particles/radius of the deck's radius runs
T.write_deck(d, 'equal.nml', LD.format(particles="position_file = 'one_species.h5'"))
status, out, err = T.run('equal.nml', d, expect_ok=False)
T.check(status == 0 and 'finished at step 2' in out, 'equal spheres with particles/radius in their file run (status %d)'
        % status)
with T.h5py.File(os.path.join(d, 'out', 'particles_00000002.h5'), 'r') as f:
    T.check(T.np.array_equal(T.np.ravel(f['particles/radius'][()]), [1.0, 1.0, 1.0]),
            'the particle snapshot holds each sphere\'s radius')
T.finish()
