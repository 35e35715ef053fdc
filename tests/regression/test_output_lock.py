"""Invariant: one run per output directory. A run locks its &output directory at start (rank 0, an
fcntl lock on DIR/.fdsusp.lock that lives as long as its process; src/runtime/os_services_c.c), so:
 1. a second run started into a directory in use is refused before it writes anything there:
    exit status 2, one message on stderr naming the directory, the deck's &output directory and
    the holder's pid; the lock file still names the first run; and the first run's series.h5 holds
    its own steps 1..N exactly once when it ends (without the lock the second run truncated it and
    the two interleaved their records);
 2. a lock left by a killed run (SIGKILL: no chance to clean up) does not block the next start:
    the kernel dropped the lock with the process; the next run takes it over, says so once naming
    the killed run's pid, and runs to its end;
 3. a run that ends (normally, or with an error) empties the lock file: the next start reports no
    stale holder.
Exact checks on statuses, messages and step numbers; no tolerance."""
import os
import signal
import subprocess
import time

import atexit

import numpy as np

import fdsusp_testlib as T

DECK = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = {steps} /
&output directory = 'out', progress_every = 1 /
"""


started = []


@atexit.register
def stop_ours():
    """The runs this test started end with it, whatever happened (each by its own pid)."""
    for p in started:
        if p.poll() is None:
            p.kill()


def start(deck, cwd):
    log = open(os.path.join(cwd, os.path.basename(deck) + '.log'), 'w+')
    p = subprocess.Popen(T.command(deck), cwd=cwd, env=T.ENV, stdout=log, stderr=subprocess.STDOUT, text=True)
    started.append(p)
    return p, log.name


def wait_for_step(p, logname, step, timeout=120):
    t0 = time.time()
    while time.time() - t0 < timeout and p.poll() is None:
        with open(logname) as f:
            if any(l.startswith('step ') and int(l.split()[1]) >= step for l in f):
                return True
        time.sleep(0.05)
    return False


def holder(d):
    """The lock file's text ('' when empty), None without a lock file."""
    path = os.path.join(d, 'out', '.fdsusp.lock')
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return f.read().strip()


d = T.scratch('output_lock')
long_deck = T.write_deck(d, 'long.nml', DECK.format(steps=100000))
short_deck = T.write_deck(d, 'short.nml', DECK.format(steps=8))

# 1. a second run into a directory in use
a, alog = start(long_deck, d)
T.check(wait_for_step(a, alog, 3), 'the first run is under way (step 3)')
status, out, err = T.run(short_deck, d, expect_ok=False)
messages = [l for l in err.splitlines() if l.strip()]
T.check(status == 2, 'the second run is refused: exit status %d == 2' % status)
T.check(len(messages) == 1 and '"out"' in messages[0] and 'in use by another run' in messages[0]
        and 'pid %d' % a.pid in messages[0] and 'short.nml' in messages[0] and '&output' in messages[0]
        and 'directory' in messages[0], 'one message naming the deck, &output directory, "out" and the holder: %s'
        % messages)
T.check('step ' not in out, 'the second run made no step')
T.check((holder(d) or '').startswith('pid %d ' % a.pid), 'the lock file still names the first run (%s)' % holder(d))
a.send_signal(signal.SIGTERM)
a.wait(timeout=120)
with open(alog) as f:
    text = f.read()
last = int(text.split('stopped by signal 15 at step ')[1].split(':')[0]) if 'stopped by signal 15 at step ' in text else -1
s = T.series(os.path.join(d, 'out'))
T.check(a.returncode == 0 and last > 3, 'the first run stopped on SIGTERM at step %d with status %d' % (last, a.returncode))
T.check(np.array_equal(s['step'], np.arange(1, last + 1)),
        'its series.h5 holds its steps 1..%d exactly once (%d records, steps %s..%s)'
        % (last, len(s['step']), s['step'][:1], s['step'][-1:]))
T.check(holder(d) == '', 'a run that ended empties the lock file')

# 2. a lock left by a killed run
k, klog = start(long_deck, d)
T.check(wait_for_step(k, klog, 2), 'another run is under way (step 2)')
T.check((holder(d) or '').startswith('pid %d ' % k.pid), 'its lock file names it (%s)' % holder(d))
k.send_signal(signal.SIGKILL)
k.wait(timeout=60)
T.check((holder(d) or '').startswith('pid %d ' % k.pid), 'killed with SIGKILL, it left its lock file behind')
status, out, err = T.run(short_deck, d, expect_ok=False)
notes = [l for l in out.splitlines() if 'taken over' in l]
T.check(status == 0 and 'finished at step 8' in out, 'the next run starts and finishes (status %d)' % status)
T.check(len(notes) == 1 and 'pid %d' % k.pid in notes[0], 'it says once that it took over the killed run\'s lock: %s'
        % notes)
T.check(holder(d) == '', 'and empties the lock file at its end')

# 3. a run that stops with an error releases the directory too
status, out, err = T.run(short_deck, d, args=['-restart', 'nowhere.h5'], expect_ok=False)
T.check(status == 2 and holder(d) == '', 'a run refused after taking the lock (missing checkpoint, status %d) '
        'leaves the lock file empty' % status)
status, out, err = T.run(short_deck, d, expect_ok=False)
T.check(status == 0 and 'taken over' not in out, 'the next start reports no stale holder')
T.finish()
