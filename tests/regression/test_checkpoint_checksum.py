"""Invariant: a damaged checkpoint is refused, never run on. Every dataset of a checkpoint carries a
checksum (the fields written by PETSc's viewer the attribute checksum, the particles, contact springs
and statistics HDF5's Fletcher-32 filter; src/io/checkpoint.F90), and a restart reads every dataset
against it before any work. So one byte flipped in the middle of a dataset's raw data (located with
h5py: the offset of its chunk, or of its contiguous data) stops the restart with exit status 2 and
one message naming the checkpoint and the dataset, for a field (/u, /p) and for datasets of the
HDF5 API (/particles/position, /rheology/accumulators). The intact checkpoint restarts, and
continues bitwise: 4 steps + restart + 2 equal 6 straight steps (every dataset and attribute of
the final checkpoints to 1e-12 of the entry's largest magnitude, at least 1, as test_restart; the
deck's output directory, which differs by construction, excepted). A checkpoint without checksums
(written before 2026-11-27: the attributes removed) still restarts, and the log says its data
could not be verified. Exact checks otherwise (bytes, message text, exit status)."""
import os
import shutil
import fdsusp_testlib as T

DNS = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5, shear_rate = 1 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = {steps} /
&output directory = '{out}', progress_every = 1 /
"""
LD = """&domain box = 6.4, 6.4, 6.4, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 0.002, steps = {steps} /
&output directory = '{out}', progress_every = 1 /
&particles number = 2, position(:,1) = 2, 3.2, 3.2, position(:,2) = 4.5, 3.2, 3.2 /
&contact roughness = 0.01, friction = 0.3 /
&rheology discard_strain = 0.004, average_strain = 0.008, blocks = 1 /
"""


def flip_middle_byte(path, name):
    """Flip one bit of the byte in the middle of dataset name's raw data; return the offset."""
    with T.h5py.File(path, 'r') as f:
        ds = f[name]
        if ds.chunks:
            info = ds.id.get_chunk_info(0)
            offset, size = info.byte_offset, info.size - (4 if ds.fletcher32 else 0)
        else:
            offset, size = ds.id.get_offset(), ds.id.get_storage_size()
    position = offset + size // 2
    with open(path, 'r+b') as f:
        f.seek(position)
        byte = f.read(1)[0]
        f.seek(position)
        f.write(bytes([byte ^ 0x10]))
    return position


def damaged(d, ckpt, name, deck):
    copy = os.path.join(d, 'damaged.h5')
    shutil.copyfile(ckpt, copy)
    flip_middle_byte(copy, name)
    before = open(copy, 'rb').read()
    shutil.rmtree(os.path.join(d, 'again'), ignore_errors=True)
    T.write_deck(d, 'r.nml', deck)
    status, out, err = T.run('r.nml', d, args=['-restart', 'damaged.h5'], expect_ok=False)
    messages = [line for line in err.splitlines() if line.startswith('fdsusp:') and 'warning' not in line]
    T.check(status == 2, '/%s flipped: refused with status %d == 2' % (name, status))
    T.check(len(messages) == 1 and 'damaged.h5' in messages[0] and 'item /%s:' % name in messages[0]
            and 'checksum' in messages[0], '/%s flipped: one message naming the file and the dataset: %s'
            % (name, messages[:1]))
    T.check(not any(line.startswith('step ') for line in out.splitlines()) and open(copy, 'rb').read() == before,
            '/%s flipped: no step taken, the file left as it was' % name)


# ---- a resolved fluid: the fields ----
d = T.scratch('checkpoint_checksum_dns')
T.run(T.write_deck(d, 'base.nml', DNS.format(steps=4, out='base')), d)
ckpt = os.path.join(d, 'base', 'checkpoint.h5')
with T.h5py.File(ckpt, 'r') as f:
    signed = sorted(n for n in f if isinstance(f[n], T.h5py.Dataset) and 'checksum' in f[n].attrs)
T.check(signed == sorted(['p', 'phi', 'u', 'v', 'w', 'u_star', 'v_star', 'w_star', 'u_star_old', 'v_star_old',
                          'w_star_old']), 'every field of the checkpoint carries its checksum: %s' % signed)
for name in ('u', 'p'):
    damaged(d, ckpt, name, DNS.format(steps=6, out='again'))

# the intact checkpoint continues bitwise
T.write_deck(d, 'r.nml', DNS.format(steps=6, out='again'))
shutil.rmtree(os.path.join(d, 'again'), ignore_errors=True)
status, out, err = T.run('r.nml', d, args=['-restart', ckpt], expect_ok=False)
T.check(status == 0 and 'carry no checksum' not in out, 'the intact checkpoint restarts (status %d)' % status)
T.run(T.write_deck(d, 'straight.nml', DNS.format(steps=6, out='straight')), d)
T.compare_h5(os.path.join(d, 'straight', 'checkpoint.h5'), os.path.join(d, 'again', 'checkpoint.h5'),
             '6 straight vs 4 + restart + 2', skip=('deck@output.directory',))

# a checkpoint without checksums (before 2026-11-27) still restarts, and the log says so
old = os.path.join(d, 'old.h5')
shutil.copyfile(ckpt, old)
with T.h5py.File(old, 'r+') as f:
    for n in signed:
        del f[n].attrs['checksum']
shutil.rmtree(os.path.join(d, 'again'), ignore_errors=True)
status, out, err = T.run('r.nml', d, args=['-restart', 'old.h5'], expect_ok=False)
notes = [line for line in out.splitlines() if 'carry no checksum' in line]
T.check(status == 0 and len(notes) == 1 and notes[0].startswith('restart: 11 datasets'),
        'a checkpoint without checksums restarts (status %d) and the log says so: %s' % (status, notes))

# ---- lubrication dynamics: the datasets of the HDF5 API (Fletcher-32) ----
d = T.scratch('checkpoint_checksum_ld')
T.run(T.write_deck(d, 'base.nml', LD.format(steps=4, out='base')), d)
ckpt = os.path.join(d, 'base', 'checkpoint.h5')
with T.h5py.File(ckpt, 'r') as f:
    T.check(f['particles/position'].fletcher32 and f['rheology/accumulators'].fletcher32,
            'the particles and the statistics carry Fletcher-32')
for name in ('particles/position', 'rheology/accumulators'):
    damaged(d, ckpt, name, LD.format(steps=6, out='again'))
T.finish()
