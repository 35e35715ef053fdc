"""Invariant: a run killed with SIGKILL (no chance to clean up) while it writes a checkpoint leaves
the previous checkpoint whole and readable, and restarting from it reproduces the uninterrupted
run exactly (issue 8). Why it holds: a checkpoint is written to checkpoint.h5.tmp, flushed to disk
and only then renamed over checkpoint.h5 (mod_checkpoint, mod_os_services publish_file), and a restart
from step n repeats the arithmetic of steps n+1.. bitwise (test_restart, test_contact_restart).

Set-up: a 64 x 32 x 64 Couette cell with two free spheres close enough for lubrication (so the
restart also covers the lubrication links), a checkpoint every step, 1 rank. The test polls the
output directory every millisecond and sends SIGKILL the moment checkpoint.h5.tmp exists, i.e. in
the middle of a checkpoint write (asserted: it caught the .tmp at least once in up to 8
attempts). Then: checkpoint.h5 opens with h5py and holds a step; fdsusp -restart runs it on to
step 40; u, v, w, p and the particle positions equal those of an uninterrupted 40-step run to
1e-12 (bitwise in practice). The previous checkpoint may be the initial state (step 0), which a run
from the start publishes before its first step."""
import os
import signal
import subprocess
import time
import h5py
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 12.8, 6.4, 12.8, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-3, steps = {steps} /
&output directory = 'out', progress_every = 1, checkpoint_every = 1 /
&particles number = 2, position(:,1) = 5.0, 3.1, 6.4, position(:,2) = 7.1, 3.3, 6.4 /
"""
NAMES = ['u', 'v', 'w', 'p', 'particles/position']

ref = T.scratch('fault_sigkill_ref')
T.run(T.write_deck(ref, 'r.nml', DECK.format(steps=40)), ref)
want = T.read_h5(os.path.join(ref, 'out', 'checkpoint.h5'), NAMES)

d = T.scratch('fault_sigkill')
deck = T.write_deck(d, 'k.nml', DECK.format(steps=40))
tmp = os.path.join(d, 'out', 'checkpoint.h5.tmp')
caught = False
for attempt in range(8):
    p = subprocess.Popen(T.command(deck), cwd=d, env=T.ENV, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    t0 = time.time()
    # let a few checkpoints be published first, then kill inside the next write
    while time.time() - t0 < 120 and p.poll() is None:
        if os.path.exists(os.path.join(d, 'out', 'checkpoint.h5')) and os.path.exists(tmp) \
                and time.time() - t0 > 1.0 + 0.3 * attempt:
            p.send_signal(signal.SIGKILL)
            caught = True
            break
        time.sleep(0.001)
    p.wait()
    if caught:
        break
    # the run finished before a write was caught: start over from scratch
    for f in ('checkpoint.h5', 'checkpoint.h5.tmp'):
        if os.path.exists(os.path.join(d, 'out', f)):
            os.remove(os.path.join(d, 'out', f))
T.check(caught, 'SIGKILL arrived while checkpoint.h5.tmp was being written (attempt %d)' % (attempt + 1))
path = os.path.join(d, 'out', 'checkpoint.h5')
try:
    with h5py.File(path, 'r') as f:
        step = int(np.ravel(f.attrs['step'])[0])
        readable = all(n in f for n in NAMES)
except (OSError, KeyError) as e:
    step, readable = -1, False
    print('checkpoint unreadable:', e)
T.check(readable and 0 <= step < 40, 'the previous checkpoint is whole and readable (step %d; 0: the initial state '
        'a run publishes before its first step)' % step)
status, out, err = T.run(deck, d, args=['-restart', path], expect_ok=False)
T.check(status == 0, 'restart from step %d runs to step 40 (status %d)' % (step, status))
if status == 0:
    got = T.read_h5(path, NAMES)
    diff = max(float(np.max(np.abs(np.asarray(got[n]) - np.asarray(want[n])))) for n in NAMES)
    T.check(diff <= 1e-12, 'killed + restarted equals uninterrupted after 40 steps (max difference %.1e)' % diff)
T.finish()
