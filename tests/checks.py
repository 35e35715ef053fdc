"""The verdict of a Python test (Python standard library only): count the checks, print each, and
decide the exit status. Shared by tests/fdsusp_testlib.py and tests/physics/pairtraj_lib.py.

Rules (doc/DESIGN.md "Tests"):
  - a test passes only when it made at least one check and none failed;
  - finish() gives that verdict (exit status 1 on failure);
  - a test that ends without finish() (an early sys.exit(0), a forgotten call) gets the same
    verdict at interpreter exit: made no check or a failed one, and its status is forced to 1.
"""
import atexit
import os
import sys

checks = 0          # checks made
failures = []       # messages of the failed ones
_finished = False


def check(condition, message):
    """Record one assertion; print it either way ('ok    ...' or 'FAIL  ...')."""
    global checks
    checks += 1
    print(('ok    ' if condition else 'FAIL  ') + message)
    sys.stdout.flush()
    if not condition:
        failures.append(message)
    return bool(condition)


def verdict():
    """None when the test passes, else the reason it fails."""
    if failures:
        return '%d check(s) failed' % len(failures)
    if checks == 0:
        return 'the test made no checks'
    return None


def finish():
    """Print the verdict and exit: status 1 unless at least one check was made and none failed."""
    global _finished
    _finished = True
    why = verdict()
    if why:
        print(why)
        sys.stdout.flush()
        sys.exit(1)
    print('all %d checks passed' % checks)
    sys.stdout.flush()


@atexit.register
def _at_exit():
    if _finished:
        return
    why = verdict()
    if why:
        print(why + ' (the test ended without finish())')
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(1)
