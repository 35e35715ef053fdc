"""Invariant: a test passes only when it made at least one check and none failed, in every
harness: the Python tests (tests/checks.py, used by fdsusp_testlib and pairtraj_lib's Checker),
the shell tests (tests/checks.sh), the Fortran unit tests (mod_unit_checks' finish, tests/unit/
unit_checks.F90), and tests/run_tests.sh itself (a test that exits 0 without a single 'ok' line
fails; a pattern that matches no test fails). Checked on tiny tests written here, each run in a
subprocess, by its exit status (exact; no tolerance):
  Python:  no check + finish -> 1; one passing check + finish -> 0; a failed check and no finish
           -> 1; no check and sys.exit(0) -> 1; a passing check and no finish -> 0; pairtraj_lib's
           Checker: done() without a check -> 1, with one -> 0;
  shell:   checks_finish without a check -> 1, with one -> 0; exit 0 without a check -> 1; a
           failed check and exit 0 -> 1;
  Fortran: finish without a check -> 1, with one -> 0 (compiled here against the built
           mod_unit_checks);
  runner:  a unit program that prints nothing and exits 0 fails, one that prints an 'ok' line
           passes; a pattern matching no test makes the run fail."""
import os
import shutil
import subprocess
import sys

import fdsusp_testlib as T

TESTS = os.path.join(T.ROOT, 'tests')
d = T.scratch('harness_verdict')


def status_of(cmd, what, want, env=None):
    p = subprocess.run(cmd, cwd=d, capture_output=True, text=True, timeout=120, env=env)
    last = (p.stdout.strip().splitlines() or [''])[-1]
    T.check(p.returncode == want, '%s: exit status %d (want %d; last line: %s)' % (what, p.returncode, want, last))
    return p


def python_test(name, body, want, what):
    """A test script in the scratch directory, run as tests/run_tests.sh runs one (its PYTHONPATH:
    tests/ and python/), and tests/physics for pairtraj_lib."""
    path = T.write_deck(d, name + '.py', 'import sys\n%s\n' % body)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(TESTS, 'physics'), TESTS,
                                                        os.path.join(T.ROOT, 'python')]))
    status_of([sys.executable, path], 'Python, ' + what, want, env=env)


python_test('none_finish', 'import fdsusp_testlib as T\nT.finish()', 1, 'no check, finish()')
python_test('one_finish', 'import fdsusp_testlib as T\nT.check(True, "holds")\nT.finish()', 0, 'one passing check, finish()')
python_test('fail_nofinish', 'import fdsusp_testlib as T\nT.check(False, "does not hold")', 1,
            'a failed check, no finish()')
python_test('none_exit0', 'import fdsusp_testlib as T\nsys.exit(0)', 1, 'no check, sys.exit(0)')
python_test('one_nofinish', 'import fdsusp_testlib as T\nT.check(True, "holds")', 0, 'a passing check, no finish()')
python_test('checker_none', 'from pairtraj_lib import Checker\nChecker().done()', 1,
            "pairtraj_lib's Checker, done() without a check")
python_test('checker_one', 'from pairtraj_lib import Checker\nc = Checker()\nc.check("holds", True)\nc.done()', 0,
            "pairtraj_lib's Checker, one passing check")


def shell_test(name, body, want, what):
    path = T.write_deck(d, name + '.sh', '. %s\n%s\n' % (os.path.join(TESTS, 'checks.sh'), body))
    status_of(['bash', path], 'shell, ' + what, want)


shell_test('none_finish', 'checks_finish', 1, 'checks_finish without a check')
shell_test('one_finish', 'check_result 0 "holds"\nchecks_finish', 0, 'one passing check, checks_finish')
shell_test('none_exit0', 'exit 0', 1, 'no check, exit 0')
shell_test('fail_exit0', 'check_result 1 "does not hold"\nexit 0', 1, 'a failed check, exit 0')

# Fortran: two programs against the built mod_unit_checks (modules and objects beside the unit tests)
unit_dir = os.environ.get('FDSUSP_UNIT_DIR') or os.path.join(T.ROOT, 'build', 'opt', 'tests')
build = os.path.dirname(unit_dir)
objects = [os.path.join(build, 'tests', 'unit', 'unit_checks.o'), os.path.join(build, 'src', 'kernels', 'kinds.o')]
fc = shutil.which('gfortran') or shutil.which('mpif90')
T.check(fc is not None and all(os.path.exists(o) for o in objects),
        'a Fortran compiler (%s) and the built mod_unit_checks (%s)' % (fc, build))
for name, body, want, what in (('none', '', 1, 'finish without a check'),
                               ('one', '  call check(.true., "holds")\n', 0, 'one passing check, finish')):
    src = T.write_deck(d, 'unit_%s.f90' % name, 'program unit_%s\n  use mod_unit_checks, only: check, finish\n'
                       '  implicit none\n%s  call finish("unit_%s")\nend program unit_%s\n' % (name, body, name, name))
    exe = os.path.join(d, 'unit_' + name)
    # linked as the Makefile links the unit tests: mod_unit_checks' min_eig calls LAPACK's dsyev
    c = subprocess.run([fc, '-I', build, src] + objects + ['-o', exe, '-llapack', '-lblas'], cwd=d,
                       capture_output=True, text=True)
    T.check(c.returncode == 0, 'Fortran: unit_%s compiles (%s)' % (name, c.stderr.strip()[-200:]))
    if c.returncode == 0:
        status_of([exe], 'Fortran, ' + what, want)

# the runner: a scratch 'unit' directory holding a silent test and a talking one
units = os.path.join(d, 'units')
os.makedirs(units)
for name, text in (('test_silent_stub', 'exit 0'), ('test_talking_stub', 'echo "  ok    holds"; exit 0')):
    with open(os.path.join(units, name), 'w') as f:
        f.write('#!/bin/sh\n%s\n' % text)
    os.chmod(os.path.join(units, name), 0o755)
runner = os.path.join(TESTS, 'run_tests.sh')
p = status_of(['bash', runner, units, units], 'run_tests.sh on a silent and a talking test', 1)
T.check('FAIL  test_silent_stub' in p.stdout and 'PASS  test_talking_stub' in p.stdout
        and p.stdout.strip().endswith('1 passed, 1 failed'),
        'run_tests.sh fails the test that made no checks and passes the other (%s)' % p.stdout.strip().splitlines()[-1:])
p = status_of(['bash', runner, units, 'no-test-has-this-in-its-path'], 'run_tests.sh with a pattern matching no test', 1)
T.check('no test matches' in p.stdout, 'run_tests.sh says no test matched')
T.finish()
