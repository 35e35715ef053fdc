"""Invariant: series.h5 survives a kill at any instant of its writing, restarts included. Whatever
write, rename or unlink a SIGKILL stops (strace injects it at the syscall's entry, so that call
and everything after it never happen), the next `fdsusp DECK -continue` ends with a series.h5
that holds each step 1..60 exactly once, every record identical to the uninterrupted run's
(wall_time excepted), and no stray part or .tmp file. Why it holds (doc/DESIGN.md "series.h5:
immutable parts, atomic consolidation"): nothing published is modified in place; parts and the
consolidated file are written as .tmp, flushed and renamed; a part is removed only after
series.h5 holds its records; a continuation consolidates up to its checkpoint's step.

Two phases are attacked:
  A. a run from the start, 60 steps, a part every 5 steps (progress lines, with
     -series_flush_seconds 0 so that each one publishes) and a checkpoint every
     20: kills spread over its HDF5 writes (pwrite64), its other writes (the log, the copies of
     consolidation), every rename and unlink;
  B. a continuation that must cut the series back: series.h5 holds steps 1..60, the checkpoint is
     the one of step 40 (the state of a run killed after its step-60 flush but before its step-60
     checkpoint); kills spread over the calls of the continuation's opening, which cuts back.
Exact comparison (rtol 0): one rank, and a continuation repeats the arithmetic of the steps it
redoes bitwise (tests/regression/test_restart.py).
Scene: lubrication dynamics, 18 rough frictional spheres in an 8a Lees-Edwards cube with the
rheology on (every column kind: scalars, vectors, 3 x N, 3 x 3 x N). ~70 runs of ~0.5 s, three at a
time (each trial in its own directory).
Needs strace (scripts/install-deps installs it)."""
import os
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
import h5py
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 8, 8, 8, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = {steps} /
&output directory = 'out', progress_every = 5, checkpoint_every = {checkpoint_every}, particles_every = 1000 /
&particles solid_fraction = 0.15, seed = 3 /
&contact roughness = 5e-3, friction = 0.5 /
&rheology discard_strain = 0.05, average_strain = 0.25, blocks = 5 /
"""
STEPS = 60
FLUSH = ['-series_flush_seconds', '0']     # every progress line publishes a part


def strace_run(deck, cwd, syscall, when):
    """Run `fdsusp DECK -continue` under strace, killed at the entry of its when-th `syscall`."""
    cmd = ['strace', '-o', '/dev/null', '-e', 'trace=' + syscall,
           '-e', 'inject=%s:signal=KILL:when=%d' % (syscall, when), T.FDSUSP, deck, '-continue'] + FLUSH
    p = subprocess.run(cmd, cwd=cwd, env=T.ENV, capture_output=True, text=True, timeout=120)
    return p.returncode


def count_calls(deck, cwd, syscalls):
    """How many of each syscall a `fdsusp DECK -continue` makes (strace's trace, one run)."""
    trace = os.path.join(cwd, 'trace.txt')
    subprocess.run(['strace', '-o', trace, '-e', 'trace=' + ','.join(syscalls), T.FDSUSP, deck, '-continue'] + FLUSH,
                   cwd=cwd, env=T.ENV, capture_output=True, text=True, timeout=120, check=True)
    counts = {s: 0 for s in syscalls}
    with open(trace) as f:
        for line in f:
            name = line.split('(')[0].strip()
            if name in counts:
                counts[name] += 1
    return counts


def spread(total, n):
    """n call numbers spread evenly over 1..total (all of them when total <= n)."""
    if total <= n:
        return list(range(1, total + 1))
    return sorted(set(int(round(x)) for x in np.linspace(1, total, n)))


def series_problem(outdir, want):
    """'' when outdir's series equals want (wall_time excepted) and no part or .tmp is left."""
    path = os.path.join(outdir, 'series.h5')
    try:
        got = T.series(outdir)
    except Exception as e:  # noqa: BLE001 (an unreadable file is the failure being looked for)
        return 'series.h5 unreadable (%s)' % e
    steps = got.get('step', np.zeros(0))
    if not np.array_equal(steps, np.arange(1, STEPS + 1)):
        return 'steps %s (%d records, %d distinct)' % (steps[:3], len(steps), len(np.unique(steps)))
    for name, value in want.items():
        if name == 'wall_time':
            continue
        if name not in got or got[name].shape != value.shape or not np.array_equal(got[name], value):
            return 'column %s differs' % name
    parts = os.path.join(outdir, 'series.parts')
    left = (os.listdir(parts) if os.path.isdir(parts) else []) + \
           [f for f in os.listdir(outdir) if f.endswith('.tmp') or '.damaged' in f]
    if left:
        return 'left behind: %s' % ', '.join(sorted(left))
    with h5py.File(path, 'r') as f:
        if set(f.attrs) != set(want_attrs):
            return 'attributes %s' % sorted(f.attrs)
    return ''


# the uninterrupted run and, beside it, the checkpoint of step 40 for phase B
ref = T.scratch('series_crash_ref')
c40 = T.scratch('series_crash_c40')
T.run_many([dict(deck=T.write_deck(ref, 'r.nml', DECK.format(steps=STEPS, checkpoint_every=20)), cwd=ref),
            dict(deck=T.write_deck(c40, 'c.nml', DECK.format(steps=40, checkpoint_every=20)), cwd=c40)])
want = T.series(os.path.join(ref, 'out'))
with h5py.File(os.path.join(ref, 'out', 'series.h5'), 'r') as f:
    want_attrs = dict(f.attrs)
T.check(np.array_equal(want['step'], np.arange(1, STEPS + 1)) and len(want_attrs) > 10,
        'reference: steps 1..%d once each, %d attributes' % (STEPS, len(want_attrs)))

work = T.scratch('series_crash')
deck = T.write_deck(work, 'k.nml', DECK.format(steps=STEPS, checkpoint_every=20))
out = os.path.join(work, 'out')


def prepare(phase, where=work):
    """A fresh output directory under where: empty (A), or the state phase B starts from."""
    target = os.path.join(where, 'out')
    shutil.rmtree(target, ignore_errors=True)
    if phase == 'B':
        shutil.copytree(os.path.join(ref, 'out'), target)
        shutil.copy(os.path.join(c40, 'out', 'checkpoint.h5'), os.path.join(target, 'checkpoint.h5'))


def trial(phase, syscall, when):
    """One kill and its continuation, in a directory of its own (the trials are independent, so
    three run at a time on the 2-core machine, which keeps both cores busy through the runs' MPI
    start-up, spent mostly waiting): '' when the series comes out whole, else the
    problem; None when the run ended before that call (nothing was killed)."""
    where = os.path.join(work, 'trial_%s_%s_%d' % (phase, syscall, when))
    shutil.rmtree(where, ignore_errors=True)
    os.makedirs(where)
    shutil.copy(deck, where)
    prepare(phase, where)
    mine = os.path.join(where, os.path.basename(deck))
    if strace_run(mine, where, syscall, when) == 0:
        return None
    rc, so, se = T.run(mine, where, args=['-continue'] + FLUSH, expect_ok=False)
    problem = 'continuation failed (%d): %s' % (rc, se.strip()[-300:]) if rc != 0 else \
        series_problem(os.path.join(where, 'out'), want)
    if not problem:
        shutil.rmtree(where, ignore_errors=True)
    return problem


SYSCALLS = ('pwrite64', 'write', 'rename', 'unlink')
PLAN = {'pwrite64': 14, 'write': 8, 'rename': 10, 'unlink': 5}
# phase B's kills are spread over its opening (the cut-back), counted on a deck that ends at the
# checkpoint's step and so does nothing else
opening = T.write_deck(work, 'o.nml', DECK.format(steps=40, checkpoint_every=20))
for phase in ('A', 'B'):
    prepare(phase)
    counts = count_calls(deck if phase == 'A' else opening, work, SYSCALLS)
    plan = [(syscall, when) for syscall in SYSCALLS for when in spread(counts[syscall], PLAN[syscall])]
    with ThreadPoolExecutor(max_workers=3) as pool:
        problems = list(pool.map(lambda sw: trial(phase, *sw), plan))
    bad = ['%s #%d: %s' % (sw[0], sw[1], pr) for sw, pr in zip(plan, problems) if pr]
    T.check(not bad, 'phase %s: %d kills (of %s calls %s) each followed by -continue give the '
            'uninterrupted series%s' % (phase, len(plan), '/'.join(SYSCALLS),
                                        '/'.join(str(counts[s]) for s in SYSCALLS),
                                        '' if not bad else ': ' + '; '.join(bad[:6])))

# a damaged series.h5 is kept aside, never silently replaced
prepare('B')
with open(os.path.join(out, 'series.h5'), 'r+b') as f:
    f.write(b'\0' * 64)                 # the superblock gone: not HDF5 any more
rc, so, se = T.run(deck, work, args=['-continue'], expect_ok=False)
kept = os.path.join(out, 'series.h5.damaged')
T.check(rc == 0 and os.path.exists(kept) and 'series.h5.damaged' in se and 'kept as' in se,
        'an unreadable series.h5 is moved to series.h5.damaged with a warning, the run goes on (%d: %s)'
        % (rc, se.strip().splitlines()[-1] if se.strip() else ''))
T.finish()
