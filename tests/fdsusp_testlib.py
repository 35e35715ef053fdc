"""Helpers shared by the fdsusp test scripts: run bin/fdsusp on a deck in a scratch directory
and read what it wrote. Needs Debian's python3 with numpy and h5py. tests/run_tests.sh puts tests/
(this library, checks.py) and the checkout's python/ (the package fdsusp) on PYTHONPATH: the one
way the tests find them (doc/DESIGN.md "Tests")."""
import os
import shutil
import signal
import subprocess
import tempfile
import time

import h5py
import numpy as np

# the verdict (shared with tests/physics/pairtraj_lib.py): check() records one assertion, finish()
# exits 1 unless at least one check was made and none failed; a test ending without finish() gets
# the same verdict at exit (tests/checks.py)
from checks import check, finish, failures  # noqa: F401

ROOT = os.environ.get('FDSUSP_ROOT', os.path.abspath(os.path.join(os.path.dirname(__file__), '..')))
# the package of this checkout (python/fdsusp): the one reader of a run's series (series.h5 and
# series.parts/) and the one way to find the programs ($FDSUSP_BIN, else this checkout's bin/)
from fdsusp import deck as fdsusp_deck, run as fdsusp_run, series as series_reader
BIN = fdsusp_run.bin_dir()
FDSUSP = fdsusp_run.program('fdsusp')

# The rank count of the tests that run the program in parallel (2 unless FDSUSP_TEST_RANKS, set by
# `make check RANKS=n`, says otherwise; doc/DESIGN.md "Tests"). Tests that compare the parallel run
# with one rank do so at this count (RANKS=1 runs the whole suite on one rank); tests of their own
# counts (test_rank_independence, test_parallel_consistency, test_fluid_direct, ...) keep them.
RANKS = int(os.environ.get('FDSUSP_TEST_RANKS', '2'))
if RANKS < 1:
    raise SystemExit('FDSUSP_TEST_RANKS must be at least 1, not %d' % RANKS)

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1',
           OMPI_MCA_rmaps_base_oversubscribe='1')

def scratch(name):
    """A fresh scratch directory under build/test-work."""
    d = os.path.join(ROOT, 'build', 'test-work', name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def write_deck(directory, name, text):
    """Write a deck (its text, or groups for fdsusp.deck.text) as directory/name; returns the path."""
    return fdsusp_deck.write(os.path.join(directory, name), text if isinstance(text, str) else fdsusp_deck.text(text))


def command(deck, np_ranks=1, args=()):
    return fdsusp_run.command(deck, np_ranks, args, binary=FDSUSP)


def run(deck, cwd, np_ranks=1, args=(), expect_ok=True, timeout=600):
    """Run fdsusp; return (exit status, stdout, stderr)."""
    p = subprocess.run(command(deck, np_ranks, args), cwd=cwd, env=ENV, capture_output=True,
                       text=True, timeout=timeout)
    if expect_ok and p.returncode != 0:
        print(p.stdout[-3000:])
        print(p.stderr[-3000:])
        raise SystemExit('fdsusp failed with status %d on %s' % (p.returncode, deck))
    return p.returncode, p.stdout, p.stderr


def run_many(runs, cores=2):
    """Run independent fdsusp runs at the same time, each as run() would (runs: a list of dicts of
    run()'s keywords: deck, cwd, np_ranks, args, expect_ok, timeout), started in the order given
    with at most `cores` ranks under way at once (the CI machine has 2 cores and runs one test at a
    time; a run of more ranks than cores runs alone). A run's result depends only on its own deck,
    directory, arguments and rank count, never on what runs beside it: running them together
    changes only the test's wall time. Returns their (status, stdout, stderr) in the order given; a
    run that fails with expect_ok (the default) stops the test as run() does, once the others have
    ended."""
    import threading
    turn = threading.Condition()
    state = {'busy': 0, 'next': 0}
    results = [None] * len(runs)
    errors = {}

    def one(k):
        kw = dict(runs[k])
        kw.pop('expect_ok', None)
        ranks = min(kw.get('np_ranks', 1), cores)
        with turn:
            turn.wait_for(lambda: state['next'] == k and state['busy'] + ranks <= cores)
            state['busy'] += ranks
            state['next'] += 1
            turn.notify_all()
        try:
            results[k] = run(expect_ok=False, **kw)
        except Exception as e:  # noqa: BLE001 (a timeout: reported by the caller's thread)
            errors[k] = e
        finally:
            with turn:
                state['busy'] -= ranks
                turn.notify_all()

    threads = [threading.Thread(target=one, args=(k,)) for k in range(len(runs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        k = min(errors)
        raise SystemExit('fdsusp on %s: %s' % (runs[k]['deck'], errors[k]))
    failed = [k for k in range(len(runs)) if runs[k].get('expect_ok', True) and results[k][0] != 0]
    for k in failed:
        print(results[k][1][-3000:])
        print(results[k][2][-3000:])
    if failed:
        raise SystemExit('fdsusp failed with status %d on %s' % (results[failed[0]][0], runs[failed[0]]['deck']))
    return results


def run_until_then_signal(deck, cwd, min_step, sig=signal.SIGTERM, np_ranks=1, timeout=300):
    """Start fdsusp, wait until its progress line reports at least min_step, send sig.
    Return (exit status, stdout)."""
    log = open(os.path.join(cwd, 'signal_run.log'), 'w+')
    p = subprocess.Popen(command(deck, np_ranks), cwd=cwd, env=ENV, stdout=log,
                         stderr=subprocess.STDOUT, text=True)
    t0 = time.time()
    while time.time() - t0 < timeout:
        time.sleep(0.05)
        log.flush()
        with open(log.name) as f:
            steps = [int(l.split()[1]) for l in f if l.startswith('step ')]
        if steps and steps[-1] >= min_step:
            break
        if p.poll() is not None:
            break
    p.send_signal(sig)
    status = p.wait(timeout=timeout)
    with open(log.name) as f:
        out = f.read()
    return status, out


def read_h5(path, names):
    with h5py.File(path, 'r') as f:
        return {n: np.array(f[n]) for n in names}


def h5_attr(path, name):
    with h5py.File(path, 'r') as f:
        return np.array(f.attrs[name])


def series(outdir):
    """Every dataset of the run's series by its path ('time', 'particles/velocity', ...): series.h5
    and the records still in series.parts/ (fdsusp.series)."""
    return series_reader.read(outdir)[0]


def h5_contents(path):
    """Every dataset and attribute of an HDF5 file by name: datasets by their path ('u',
    'particles/position'), attributes as 'OWNER@name' ('@step' on the root, 'contacts@count')."""
    out = {}
    with h5py.File(path, 'r') as f:
        for k, v in f.attrs.items():
            out['@' + k] = np.array(v)

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = np.array(obj)
            for k, v in obj.attrs.items():
                out[name + '@' + k] = np.array(v)
        f.visititems(visit)
    return out


def compare_h5(path_a, path_b, what, skip=(), rtol=1e-12):
    """Check that two HDF5 files hold the same datasets and attributes (names in skip excepted)
    with the same values: numbers to rtol of the entry's largest magnitude (at least 1), anything
    else exactly; one check per entry. Returns the names compared."""
    a, b = h5_contents(path_a), h5_contents(path_b)
    names_a = sorted(n for n in a if n not in skip)
    names_b = sorted(n for n in b if n not in skip)
    check(names_a == names_b, '%s: the same %d datasets and attributes (only in the first: %s; only in the '
          'second: %s)' % (what, len(names_a), sorted(set(names_a) - set(names_b)) or 'none',
                           sorted(set(names_b) - set(names_a)) or 'none'))
    for n in names_a:
        if n not in b:
            continue
        x, y = a[n], b[n]
        if x.shape != y.shape:
            check(False, '%s: %s has shape %s and %s' % (what, n, x.shape, y.shape))
        elif x.dtype.kind in 'fiub' and y.dtype.kind in 'fiub':
            x, y = x.astype(float), y.astype(float)
            same_nan = np.array_equal(np.isnan(x), np.isnan(y))
            diff = float(np.nanmax(np.abs(x - y), initial=0.0))
            scale = max(1.0, float(np.nanmax(np.abs(x), initial=0.0)))
            where = ''
            if diff > 0:
                k = np.unravel_index(np.nanargmax(np.abs(x - y)), x.shape)
                where = ' at %s: %r vs %r' % (k, x[k], y[k])
            check(same_nan and diff <= rtol * scale, '%s: %s max difference %.1e <= %.0e x %.3g%s'
                  % (what, n, diff, rtol, scale, where))
        else:
            check(np.array_equal(x, y), '%s: %s identical' % (what, n))
    return names_a
