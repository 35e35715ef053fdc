"""Invariants of the series' growth (doc/DESIGN.md "series.h5: immutable parts, atomic
consolidation"):
  1. rank 0's buffer of records is bounded: a run that writes no progress line and no checkpoint
     (progress_every 1e8, checkpoint_every 0) still publishes its records whenever a part's worth
     is buffered (-series_part_mb, 64 MiB by default; 0.1 MiB here, 13 records of this scene). A
     SIGKILL at the entry of its 7th rename (series.h5, checkpoint of step 0, then part,
     consolidation, part, consolidation) leaves a series of two whole parts: steps 1..2k once each,
     k >= 10. Before 2026-11-27 the records stayed in memory to the end (259 MB for 4000 steps of
     the demo), and such a kill left none.
  3. memory does not grow with the records written: the fluid-free demo (72 spheres, 27 kB a
     record, a part at every progress line) peaks at the same resident size after 2000 steps as
     after 500, within 10 MB (each run's own peak, os.wait4). Before the column functions
     filled their arrays element by element, gfortran leaked every record's values: +40 MB.
  2. the size the series will reach is on the log before the first step, with a warning naming the
     free space when the disk cannot hold it: 10^9 steps of this scene project ~7.9 TB (before: not a
     word). The run is stopped by SIGTERM after its first step (status 0, a checkpoint).
Scene: lubrication dynamics, 18 rough frictional spheres in an 8a Lees-Edwards cube with the
rheology on. Needs strace (scripts/install-deps)."""
import os
import re
import subprocess
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 8, 8, 8, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = {steps} /
&output directory = 'out', progress_every = {progress}, checkpoint_every = 0, particles_every = 100000000 /
&particles solid_fraction = 0.15, seed = 3 /
&contact roughness = 5e-3, friction = 0.5 /
&rheology discard_strain = 0.05, average_strain = 0.25, blocks = 5 /
"""

# 1. the bounded buffer
d = T.scratch('series_bounds')
deck = T.write_deck(d, 'b.nml', DECK.format(steps=300, progress=100000000))
cmd = ['strace', '-o', '/dev/null', '-e', 'trace=rename', '-e', 'inject=rename:signal=KILL:when=7',
       T.FDSUSP, deck, '-series_part_mb', '0.1']
p = subprocess.run(cmd, cwd=d, env=T.ENV, capture_output=True, text=True, timeout=300)
T.check(p.returncode != 0, 'the run was killed at its 7th rename (status %d)' % p.returncode)
steps = T.series(os.path.join(d, 'out'))['step']
k = len(steps) // 2
T.check(k >= 10 and len(steps) == 2 * k and np.array_equal(steps, np.arange(1, 2 * k + 1)),
        'without progress lines or checkpoints, two parts reached the disk: steps 1..%d once each '
        '(%d records a part)' % (len(steps), k))

# 2. the projected size
e = T.scratch('series_projection')
status, out = T.run_until_then_signal(T.write_deck(e, 'p.nml', DECK.format(steps=1000000000, progress=1)), e, 1)
m = re.search(r'series\.h5: about ([0-9.]+) GB at the end of this run \(([0-9.]+) GB free', out)
T.check(status == 0 and m is not None and float(m.group(1)) > 1.0e3,
        'the log projects the series: %s' % (m.group(0) if m else out[-300:]))
T.check('fdsusp: warning: series.h5 will need about' in out and 'GB are free in out' in out,
        'a warning says the disk cannot hold it and how much is free')

# 3. memory against the records written
demo = open(os.path.join(T.ROOT, 'input', 'demo_lubrication_dynamics.nml')).read()
peaks = []
children = {}
for steps in (2000, 500):         # the two runs at once, one on each core (each in its own directory)
    f = T.scratch('series_memory_%d' % steps)
    text = demo.replace("out/demo_ld", "out").replace("dt = 5.0e-3", "dt = 5.0e-3, steps = %d" % steps)
    deck = T.write_deck(f, 'm.nml', text)
    children[steps] = subprocess.Popen(T.command(deck, 1, ['-series_flush_seconds', '0']), cwd=f, env=T.ENV,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
for steps in (500, 2000):
    child = children[steps]
    _, status, usage = os.wait4(child.pid, 0)      # this child's own peak, not the test's others
    child.returncode = os.waitstatus_to_exitcode(status)
    T.check(child.returncode == 0, '%d steps of the fluid-free demo run (status %d)' % (steps, child.returncode))
    peaks.append(usage.ru_maxrss / 1024.0)
T.check(peaks[1] - peaks[0] < 10.0, 'peak resident size after 500 and 2000 steps: %.1f and %.1f MB (growth < 10 MB)'
        % tuple(peaks))
T.finish()
