"""Invariant: a run killed after its last checkpoint but before its last outputs were published
loses nothing: `fdsusp DECK -continue` restarts from that checkpoint at the last step, takes no
step, and writes the last fields and particle snapshot again, the same as the uninterrupted run
wrote them (every dataset and attribute to 1e-12 of its largest magnitude, bitwise in practice:
the same state written by the same code), over the .tmp files the killed run left. Until
2026-11-29 such a continuation ended without them (the end-of-run outputs were written only when
the run had taken a step), which test_series_crash met only when a kill happened to land there.
The kill is made deterministic here: the uninterrupted run's last snapshot and field file are
replaced by the half-written .tmp files a kill before their rename leaves."""
import glob
import os
import shutil
import fdsusp_testlib as T

DECK = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = 6 /
&output directory = 'out', progress_every = 3, checkpoint_every = 6, particles_every = 3, fields_every = 3 /
&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /
"""

d = T.scratch('continue_at_end')
deck = T.write_deck(d, 'd.nml', DECK)
T.run(deck, d)
out = os.path.join(d, 'out')
last = ['particles_00000006.h5', 'fields_00000006.h5']
T.check(all(os.path.exists(os.path.join(out, f)) for f in last) and
        int(T.h5_attr(os.path.join(out, 'checkpoint.h5'), 'step')[0]) == 6,
        'the run wrote its last snapshot, fields and the checkpoint of step 6')
keep = os.path.join(d, 'uninterrupted')
os.makedirs(keep)
for f in last:
    shutil.copy(os.path.join(out, f), keep)
    # a kill between the write of the .tmp and its rename
    os.rename(os.path.join(out, f), os.path.join(out, f + '.tmp'))
    with open(os.path.join(out, f + '.tmp'), 'r+b') as h:
        h.truncate(100)
T.run(deck, d, args=['-continue'])
for f in last:
    path = os.path.join(out, f)
    T.check(os.path.exists(path), '-continue at the last step writes %s again' % f)
    if os.path.exists(path):
        T.compare_h5(os.path.join(keep, f), path, '%s as the uninterrupted run wrote it' % f)
left = glob.glob(os.path.join(out, '*.tmp'))
T.check(not left, 'no .tmp file is left (%s)' % [os.path.basename(p) for p in left])
T.finish()
