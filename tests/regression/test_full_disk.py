"""Invariant: a run whose disk fills up stops at once, on every rank, with status 3 and one message
that names the file it was writing and says that the disk is full; what it published before stays
whole: the last checkpoint opens and holds a step, and the series (series.h5 and series.parts/,
scripts/series.py) holds steps 1..k once each, every record equal to the same run's on a roomy
disk (exactly: same binary, same rank count). Nothing hangs (each run has 120 s).
Why it holds: every write of the output is checked (mod_series, mod_particles_io, mod_output,
mod_summary_io, mod_checkpoint name the file and ask mod_file_services for the cause), files are
published by rename after a whole write, and before a parallel write (fields, checkpoints) rank 0
checks the free space and all ranks stop together: in parallel HDF5 rank 0 alone writes the
metadata, so a failure there would leave the other ranks waiting.
How: the run's directory is a small tmpfs mounted in a private mount namespace (`unshare -m`, or
`unshare -r -m` for a user that is not root), at sizes chosen so that the disk fills in different
files: the fluid-free run's series (1.5 and 2.5 MB), a 2-rank DNS's field snapshots and
checkpoints (5 and 9 MB)."""
import os
import shutil
import subprocess
import h5py
import numpy as np
import fdsusp_testlib as T

LD = """&domain box = 8, 8, 8, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = 600 /
&output directory = 'out', progress_every = 20 /
&particles solid_fraction = 0.15, seed = 3 /
&contact roughness = 5e-3, friction = 0.5 /
&rheology discard_strain = 0.5, average_strain = 2.5, blocks = 5 /
"""
DNS = """&domain box = 8, 8, 8, cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-3, steps = 20 /
&output directory = 'out', progress_every = 5, fields_every = 5, checkpoint_every = 10 /
&particles number = 1, position(:,1) = 4.0, 4.0, 4.0 /
"""


def on_small_disk(deck_text, size, name, np_ranks):
    """Run the deck in a tmpfs of `size` mounted for this run alone; return (status, stderr,
    directory holding a copy of what the run left)."""
    d = T.scratch(name)
    mnt = os.path.join(d, 'mnt')
    left = os.path.join(d, 'left')
    os.makedirs(mnt)
    os.makedirs(left)
    T.write_deck(d, 'deck.nml', deck_text)
    # every progress line publishes its records (else a run this short publishes none before the
    # disk is full: the default is at most one part every 5 s)
    run = ' '.join(T.command('deck.nml', np_ranks, ['-series_flush_seconds', '0']))
    script = ('mount -t tmpfs -o size=%s tmpfs %s && cp %s/deck.nml %s && cd %s && '
              '{ timeout 120 %s > %s/stdout 2> %s/stderr; echo $? > %s/status; }; cp -a %s/. %s/'
              % (size, mnt, d, mnt, mnt, run, d, d, d, mnt, left))
    ns = ['unshare', '-m'] if os.geteuid() == 0 else ['unshare', '-r', '-m']
    p = subprocess.run(ns + ['sh', '-c', script], env=T.ENV, capture_output=True, text=True, timeout=300)
    if not os.path.exists(os.path.join(d, 'status')):
        raise SystemExit('cannot mount a tmpfs in a private namespace: %s' % p.stderr.strip())
    status = int(open(os.path.join(d, 'status')).read())
    return status, open(os.path.join(d, 'stderr')).read(), os.path.join(left, 'out')


def check_stop(what, deck_text, size, np_ranks, reference):
    status, err, out = on_small_disk(deck_text, size, 'full_disk_%s_%s' % (what, size), np_ranks)
    fatal = [l for l in err.splitlines() if l.startswith('fdsusp: fatal:')]
    T.check(status == 3 and len(fatal) == 1 and 'the disk is full' in fatal[0] and ' out/' in fatal[0],
            '%s, %s disk: status %d, one message naming the file and the full disk: %s'
            % (what, size, status, fatal[0][len('fdsusp: fatal: '):] if fatal else err.strip()[-300:]))
    with h5py.File(os.path.join(out, 'checkpoint.h5'), 'r') as f:
        step = int(np.ravel(f.attrs['step'])[0])
    T.check(True, '%s, %s disk: checkpoint.h5 opens, step %d' % (what, size, step))
    got = T.series(out)
    k = len(got['step'])
    same = [n for n in reference if n != 'wall_time' and np.array_equal(got[n], reference[n][:k])]
    T.check(k > 0 and np.array_equal(got['step'], np.arange(1, k + 1)) and len(same) == len(reference) - 1,
            '%s, %s disk: the series holds steps 1..%d once each, %d of %d columns equal to the roomy '
            'run\'s first records' % (what, size, k, len(same), len(reference) - 1))


for what, text, ranks, sizes in (('fluid-free', LD, 1, ('1500k', '2500k')), ('DNS', DNS, T.RANKS, ('5000k', '9000k'))):
    ref = T.scratch('full_disk_ref_' + what)
    T.run(T.write_deck(ref, 'r.nml', text), ref, np_ranks=ranks)
    reference = T.series(os.path.join(ref, 'out'))
    for size in sizes:
        check_stop(what, text, size, ranks, reference)
T.finish()
