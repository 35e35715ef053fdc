"""Invariants of bin/fdsusp-pack (issue 4):
1. The shipped decks run: input/pack_periodic.nml writes out/pack_periodic/packing.h5 with 2000
   spheres in a triply periodic cube at phi = 0.3, input/pack_couette.nml writes
   out/pack_couette/packing.h5 with 859 spheres in the 20a Couette cube (phi = 0.45 within the
   rounding of N, 0.5 %). Each file holds particles/position (N x 3, units of a) with attribute
   box (Lx, Ly, Lz); no two spheres overlap (|r| >= 2a, minimum image, O(N^2) numpy check
   independent of the Fortran code) and in the Couette cell a <= y <= Ly - a; every periodic
   coordinate lies in [0, L). Wall-clock times are printed (the acceptance asks under a minute
   for N = 1000 at phi = 0.45).
2. Reproducible from the seed: the same deck gives bit-identical positions; another seed does not.
3. fdsusp loads the file (&particles position_file) and takes a step.
4. Bad decks stop before any work, non-zero status, one message naming the file, the group and
   the variable (as for fdsusp's deck); no packing file is written. Among them the mixtures'
   (doc/PACKING_INPUT.md): shares not adding up to 1, a negative radius, lists of different
   lengths, both shares given, a mixture without shares, a smallest radius other than 1.
5. A mixture (radius = 1, 1.4, volume_share = 0.5, 0.5) in the Couette cell at phi = 0.55:
   particles/radius holds N radii, species 1 and 1.4 in the counts of the attributes
   species_count (nearest to the volume shares: each species within half a sphere of its share
   of the solid volume), no pair closer than a_i + a_j, no sphere closer to a wall than a_i;
   equal spheres write particles/radius too (all 1).
6. A mixture by number_share with n_particles: the counts are the shares of N exactly."""
import os
import shutil
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
import fdsusp_testlib as T
import h5py
import numpy as np

PACK = os.path.join(T.BIN, 'fdsusp-pack')
d = T.scratch('pack_program')


def pack(deck, expect_ok=True, cwd=d):
    t0 = time.time()
    p = subprocess.run([PACK, deck], cwd=cwd, env=T.ENV, capture_output=True, text=True, timeout=300)
    if expect_ok and p.returncode != 0:
        print(p.stdout[-2000:], p.stderr[-2000:])
        raise SystemExit('fdsusp-pack failed on %s' % deck)
    return p, time.time() - t0


# Every packing below is independent of the others (each its own deck and output directory; the bad
# decks each in a directory of their own), so all are started here, four at a time (the bad decks
# spend their time on MPI start-up), longest first, and each is checked where its section stands:
# started(name) is its (CompletedProcess, seconds). The times printed are then those of runs
# sharing the 2 cores.
pool = ThreadPoolExecutor(max_workers=4)
futures = {}


def start(name, deck, text=None, cwd=d, expect_ok=True, inputs=()):
    """Write text (None: no deck) as cwd/deck, copy the inputs into cwd, start fdsusp-pack on it."""
    os.makedirs(cwd, exist_ok=True)
    for path in inputs:
        shutil.copy(path, cwd)
    if text is not None:
        T.write_deck(cwd, deck, text)
    futures[name] = pool.submit(pack, deck, expect_ok, cwd)


def started(name):
    return futures[name].result()


MIX = """&packing
  box = 16, 16, 16
  y_boundary = 'walls'
  phi = 0.55
  radius = 1.0, 1.4
  volume_share = 0.5, 0.5
  seed = 4
  mc_sweeps = 100
  directory = 'out/mix'
/
"""
MIXN = """&packing
  box = 1, 1, 1
  y_boundary = 'periodic'
  phi = 0.3
  n_particles = 301
  radius = 1.4, 1.0
  number_share = 0.3, 0.7
  mc_sweeps = 10
  directory = 'out/mixn'
/
"""
start('mix', 'mix.nml', MIX)
for name in ('pack_periodic', 'pack_couette'):
    shutil.copy(os.path.join(T.ROOT, 'input', name + '.nml'), d)
    start(name, name + '.nml')
# the same deck again, in a directory of its own (section 2)
start('again', 'pack_couette.nml', cwd=os.path.join(d, 'again'), inputs=[os.path.join(d, 'pack_couette.nml')])
with open(os.path.join(d, 'pack_couette.nml')) as f:
    text = f.read()
start('seed2', 'seed2.nml', text.replace('seed = 1', 'seed = 2').replace("'out/pack_couette'", "'out/seed2'"))
start('mixn', 'mixn.nml', MIXN)


def load(path):
    with h5py.File(path, 'r') as f:
        x = np.array(f['particles/position'])
        box = np.array(f['particles/position'].attrs['box'])
    return x, box


def min_pair_distance(x, box, periodic, radius=None):
    """min |r| (minimum image), or min |r| - a_i - a_j when radius is given."""
    best = np.inf
    for i in range(len(x) - 1):
        r = x[i + 1:] - x[i]
        for k in range(3):
            if periodic[k]:
                r[:, k] -= box[k] * np.round(r[:, k] / box[k])
        d = np.sqrt((r * r).sum(axis=1))
        if radius is not None:
            d -= radius[i + 1:] + radius[i]
        best = min(best, d.min())
    return best


# ---- 1. the shipped decks
for name, n_expected, phi, periodic in [('pack_periodic', 2000, 0.3, (True, True, True)),
                                        ('pack_couette', 859, 0.45, (True, False, True))]:
    p, seconds = started(name)
    path = os.path.join(d, 'out', name, 'packing.h5')
    T.check(os.path.exists(path), '%s: wrote out/%s/packing.h5 (%.1f s)' % (name, name, seconds))
    x, box = load(path)
    with h5py.File(path, 'r') as f:
        T.check(np.array_equal(f['particles/radius'][()], np.ones(len(x))), '%s: particles/radius, all 1' % name)
    n = len(x)
    phin = n * 4 * np.pi / 3 / box.prod()
    dmin = min_pair_distance(x, box, periodic)
    print('%s: N = %d, box = %s, phi = %.5f, min |r| = %.6f a, %.1f s' % (name, n, box, phin, dmin, seconds))
    T.check(x.shape == (n_expected, 3), '%s: particles/position is N x 3 with N = %d' % (name, n_expected))
    T.check(abs(phin / phi - 1) < 0.005, '%s: phi within 0.5 %% of %.2f' % (name, phi))
    T.check(dmin >= 2.0, '%s: no overlapping spheres' % name)
    inside = all((x[:, k] >= 0).all() and (x[:, k] < box[k]).all() for k in range(3) if periodic[k])
    T.check(inside, '%s: periodic coordinates in [0, L)' % name)
    if not periodic[1]:
        T.check(x[:, 1].min() >= 1.0 and x[:, 1].max() <= box[1] - 1.0, '%s: no sphere overlaps a wall' % name)
    if name == 'pack_periodic':
        T.check(np.allclose(box, (2000 * 4 * np.pi / 3 / 0.3) ** (1 / 3), rtol=1e-12), '%s: cube side for 2000 spheres' % name)
    else:
        T.check((box == 20).all(), '%s: box attribute (20, 20, 20)' % name)

# ---- 2. reproducible
first, _ = load(os.path.join(d, 'out', 'pack_couette', 'packing.h5'))
started('again')
again, _ = load(os.path.join(d, 'again', 'out', 'pack_couette', 'packing.h5'))
T.check(np.array_equal(first, again), 'same deck, bit-identical positions')
started('seed2')
other, _ = load(os.path.join(d, 'out', 'seed2', 'packing.h5'))
T.check(not np.allclose(first, other), 'another seed, other positions')

# ---- 3. fdsusp reads the packing (a/Delta = 2 has no calibrated table: the simple lubrication
#         model, which needs none)
T.write_deck(d, 'run.nml', """&domain box = 20, 20, 20, cells_per_radius = 2 /
&time dt = 0.001, steps = 1 /
&output directory = 'run_out', progress_every = 1 /
&particles position_file = 'out/pack_couette/packing.h5', motion = 'free' /
&lubrication model = 'simple' /
""")
status, out, err = T.run('run.nml', d, expect_ok=False)
T.check(status == 0 and '859 rigid spheres' in out, 'fdsusp loads the packing (859 spheres) and steps')

# ---- 4. bad decks
GOOD = """&packing
  box = 12, 12, 12
  y_boundary = 'walls'
  phi = 0.3
  seed = 3
  mc_sweeps = 10
  directory = 'bad_out'
/
"""
with open(os.path.join(d, 'a_file'), 'w') as f:
    f.write('not a directory')
cases = [
    ('unknown variable', GOOD.replace('phi = 0.3', 'phii = 0.3'), ['bad.nml', '&packing', 'phii', 'unknown variable']),
    ('phi out of range', GOOD.replace('phi = 0.3', 'phi = 0.65'), ['bad.nml', '&packing', 'phi', 'out of range']),
    ('wrong type', GOOD.replace('seed = 3', "seed = 'x'"), ['bad.nml', '&packing', 'seed', 'cannot read']),
    ('bad y_boundary', GOOD.replace("'walls'", "'wall'"), ['bad.nml', '&packing', 'y_boundary']),
    ('box too small', GOOD.replace('box = 12, 12, 12', 'box = 12, 3, 12'), ['bad.nml', '&packing', 'box(y)', 'at least 4']),
    ('negative sweeps', GOOD.replace('mc_sweeps = 10', 'mc_sweeps = -1'), ['bad.nml', '&packing', 'mc_sweeps', 'out of range']),
    ('min_gap too large for phi', GOOD.replace('phi = 0.3', 'phi = 0.55, min_gap = 0.1'), ['bad.nml', '&packing', 'min_gap']),
    ('no sphere', GOOD.replace('phi = 0.3', 'phi = 1e-4'), ['bad.nml', '&packing', 'phi', 'no sphere']),
    ('file with a directory', GOOD.replace("directory = 'bad_out'", "directory = 'bad_out', file = 'x/p.h5'"), ['bad.nml', '&packing', 'file']),
    ('unwritable directory', GOOD.replace("'bad_out'", "'a_file/out'"), ['bad.nml', '&packing', 'directory', 'cannot be created']),
    ('unknown group', GOOD + '&domain box = 1, 1, 1 /\n', ['bad.nml', '&domain', 'unknown group']),
    ('missing group', '! nothing here\n', ['bad.nml', '&packing', 'missing']),
    ('missing deck', None, ['bad.nml', 'does not exist']),
    ('shares not adding up to 1', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, 1.4, volume_share = 0.5, 0.4'),
     ['bad.nml', '&packing', 'volume_share', 'add up to']),
    ('negative radius', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, -1.4, volume_share = 0.5, 0.5'),
     ['bad.nml', '&packing', 'radius', 'must be positive']),
    ('lists of different lengths', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, 1.4, number_share = 0.2, 0.3, 0.5'),
     ['bad.nml', '&packing', 'number_share', '3 entries, radius 2']),
    ('both shares', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, 1.4, volume_share = 0.5, 0.5, number_share = 0.5, 0.5'),
     ['bad.nml', '&packing', 'number_share', 'together with volume_share']),
    ('negative share', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, 1.4, volume_share = 1.2, -0.2'),
     ['bad.nml', '&packing', 'volume_share', 'must be in (0, 1]']),
    ('mixture without shares', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 1, 1.4'),
     ['bad.nml', '&packing', 'volume_share', 'needs volume_share or number_share']),
    ('smallest radius not 1', GOOD.replace('phi = 0.3', 'phi = 0.3, radius = 2, 1.4, volume_share = 0.5, 0.5'),
     ['bad.nml', '&packing', 'radius', 'must be 1']),
    ('mixture above phi_max', GOOD.replace('phi = 0.3', 'phi = 0.7, radius = 1, 1.4, volume_share = 0.5, 0.5'),
     ['bad.nml', '&packing', 'phi', 'out of range']),
]
for k, (name, text, words) in enumerate(cases):
    start('bad %d' % k, 'bad.nml', text, cwd=os.path.join(d, 'bad_%d' % k), expect_ok=False,
          inputs=[os.path.join(d, 'a_file')])
for k, (name, text, words) in enumerate(cases):
    p, _ = started('bad %d' % k)
    messages = [l for l in p.stderr.splitlines() if l.startswith('fdsusp')]
    T.check(p.returncode != 0, '%s: exit status %d != 0' % (name, p.returncode))
    T.check(len(messages) == 1, '%s: one message: %s' % (name, messages[:1]))
    T.check(all(w in p.stderr for w in words), '%s: the message names %s' % (name, ', '.join(words)))
    T.check(not os.path.exists(os.path.join(d, 'bad_%d' % k, 'bad_out', 'packing.h5')), '%s: no packing written' % name)

# ---- 5. a mixture in the Couette cell
p, seconds = started('mix')
with h5py.File(os.path.join(d, 'out', 'mix', 'packing.h5'), 'r') as f:
    x = np.array(f['particles/position'])
    box = np.array(f['particles/position'].attrs['box'])
    radius = np.array(f['particles/radius'])
    species_radius = np.array(f['particles'].attrs['species_radius'])
    species_count = np.array(f['particles'].attrs['species_count'])
    phi_file = float(f.attrs['phi'])
v = 4 * np.pi / 3 * species_radius ** 3
counts = [int((radius == a).sum()) for a in species_radius]
print('mixture: N = %d, counts %s, phi = %.5f, %.1f s' % (len(x), species_count, phi_file, seconds))
T.check(radius.shape == (len(x),), 'mixture: particles/radius holds N radii')
T.check(list(species_radius) == [1.0, 1.4] and counts == list(species_count), 'mixture: radii 1 and 1.4 in the counts of species_count')
T.check(all(abs(species_count * v - 0.5 * 0.55 * box.prod()) <= v / 2), 'mixture: each species within half a sphere of its volume share')
T.check(abs(phi_file - (radius ** 3).sum() * 4 * np.pi / 3 / box.prod()) < 1e-12, 'mixture: phi attribute is the packing\'s')
T.check(min_pair_distance(x, box, (True, False, True), radius) >= 0, 'mixture: no pair closer than a_i + a_j')
T.check((x[:, 1] - radius).min() >= -1e-12 and (box[1] - x[:, 1] - radius).min() >= -1e-12, 'mixture: no sphere closer to a wall than a_i')
T.check('species 2: radius 1.4000 a' in p.stdout, 'mixture: the log lists the species')

# ---- 6. number shares with n_particles
started('mixn')
with h5py.File(os.path.join(d, 'out', 'mixn', 'packing.h5'), 'r') as f:
    radius = np.array(f['particles/radius'])
    box = np.array(f['particles/position'].attrs['box'])
T.check([int((radius == 1.4).sum()), int((radius == 1.0).sum())] == [90, 211], 'number shares: 90 + 211 of 301 (largest remainder)')
T.check(abs((radius ** 3).sum() * 4 * np.pi / 3 / box.prod() - 0.3) < 1e-12, 'number shares: phi exact with n_particles')
T.finish()
