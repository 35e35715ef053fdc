"""Invariant: every test finds the programs and inputs relative to the checkout it belongs to
(or through FDSUSP_ROOT / FDSUSP_BIN, which tests/run_tests.sh exports), never through a path of
one particular machine.
 1. static: no file under tests/, scripts/ or python/ (the package), nor the Makefile, names the absolute path of this
    checkout or that of the machine where the project was first developed;
 2. dynamic: tests/physics/pairtraj_lib.py (with the package fdsusp, which finds its programs)
    and tests/physics/test_pairtraj_deck_errors.sh, copied into a scratch checkout whose
    bin/pairtraj is a stand-in that records its calls, and run from another directory without
    FDSUSP_ROOT and FDSUSP_BIN (the library on PYTHONPATH as tests/run_tests.sh puts it), use that
    checkout: the library's ROOT and PAIRTRAJ point into it and the shell test calls the stand-in
    (before, both defaulted to that machine's bin/, and the library's ROOT to the current directory).
Exact string and path comparisons, no tolerance."""
import os
import shutil
import subprocess
import sys

import fdsusp_testlib as T

ROOT = os.path.realpath(T.ROOT)
FORBIDDEN = sorted({ROOT, '/work' + '/main'})      # spelled apart so that this file passes its own scan

# 1. static scan
offenders = []
files = [os.path.join(ROOT, 'Makefile')]
for top in ('tests', 'scripts', 'python'):
    for dirpath, _, names in os.walk(os.path.join(ROOT, top)):
        files += [os.path.join(dirpath, n) for n in names]
for path in files:
    try:
        with open(path, encoding='utf-8') as f:
            text = f.read()
    except (UnicodeDecodeError, OSError):
        continue                                    # binary files (compiled tests, figures)
    for bad in FORBIDDEN:
        for k, line in enumerate(text.splitlines(), 1):
            if bad in line:
                offenders.append('%s:%d (%s)' % (os.path.relpath(path, ROOT), k, bad))
T.check(len(files) > 20 and not offenders, 'none of %d files under tests/, scripts/, python/ and the Makefile names %s%s'
        % (len(files), ' or '.join(FORBIDDEN), (': ' + ', '.join(offenders[:5])) if offenders else ''))

# 2. a scratch checkout with a stand-in pairtraj that records its calls
d = T.scratch('checkout_paths')
other = os.path.join(d, 'checkout')
os.makedirs(os.path.join(other, 'tests', 'physics'))
os.makedirs(os.path.join(other, 'bin'))
os.makedirs(os.path.join(other, 'src', 'programs'))        # what fdsusp.run.checkout() knows a checkout by
for name in ('physics/pairtraj_lib.py', 'physics/test_pairtraj_deck_errors.sh', 'checks.py', 'checks.sh'):
    if os.path.exists(os.path.join(ROOT, 'tests', name)):
        shutil.copy(os.path.join(ROOT, 'tests', name), os.path.join(other, 'tests', name))
shutil.copytree(os.path.join(ROOT, 'python', 'fdsusp'), os.path.join(other, 'python', 'fdsusp'),
                ignore=shutil.ignore_patterns('__pycache__'))
calls = os.path.join(d, 'calls.txt')
stand_in = os.path.join(other, 'bin', 'pairtraj')
with open(stand_in, 'w') as f:
    f.write('#!/bin/sh\necho "$0 $*" >> %s\necho "stand-in pairtraj" >&2\nexit 2\n' % calls)
os.chmod(stand_in, 0o755)
env = {k: v for k, v in os.environ.items() if k not in ('FDSUSP_ROOT', 'FDSUSP_BIN')}
elsewhere = os.path.join(d, 'elsewhere')
os.makedirs(elsewhere)

# (the probe makes one check: a script that imports the harness and checks nothing fails)
probe = 'import pairtraj_lib as L; print("ROOT=" + L.ROOT); print("BIN=" + L.PAIRTRAJ); L.checks.check(True, "probe")'
p = subprocess.run([sys.executable, '-c', probe], cwd=elsewhere,
                   env=dict(env, PYTHONPATH=os.pathsep.join(os.path.join(other, *sub) for sub in
                                                            (('tests', 'physics'), ('tests',), ('python',)))),
                   capture_output=True, text=True)
lines = [l.split('=', 1)[1] for l in p.stdout.splitlines() if l.startswith(('ROOT=', 'BIN='))]
T.check(p.returncode == 0 and len(lines) == 2 and os.path.realpath(lines[0]) == os.path.realpath(other),
        'pairtraj_lib: ROOT is the checkout holding it (%s)' % (lines[:1] or p.stderr[-300:]))
T.check(len(lines) == 2 and os.path.realpath(lines[1]) == os.path.realpath(stand_in),
        'pairtraj_lib: PAIRTRAJ is that checkout\'s bin/pairtraj (%s)' % lines[1:])

subprocess.run(['bash', os.path.join(other, 'tests', 'physics', 'test_pairtraj_deck_errors.sh')], cwd=elsewhere,
               env=env, capture_output=True, text=True, timeout=120)
called = open(calls).read().splitlines() if os.path.exists(calls) else []
T.check(len(called) > 0 and all(os.path.realpath(c.split()[0]) == os.path.realpath(stand_in) for c in called),
        'test_pairtraj_deck_errors.sh calls the bin/pairtraj of its own checkout (%d calls)' % len(called))
T.finish()
