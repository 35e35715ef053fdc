"""fdsusp.plots draws its figures; every command-line script answers --help and imports no other
script."""
import ast
import glob
import os
import subprocess
import sys

import pytest

from conftest import ROOT
from test_rheology import synthetic
from fdsusp import rheology

pytest.importorskip('matplotlib')
from fdsusp import plots  # noqa: E402


def test_run_figures(tmp_path):
    """Run b measured the order (structure/q6): rheology.load returns its columns and its figure
    draws them; run a did not, and loads and draws without them."""
    runs = []
    for name, order in (('a', False), ('b', True)):
        d = synthetic(str(tmp_path / name / 'out'), order=order)
        a, s = rheology.load(d)
        assert ('structure/q6' in s) == order
        runs.append((d, a, s, rheology.summarise(a, s)))
    plots.run_figures(runs, str(tmp_path / 'plots'))
    assert sorted(os.listdir(tmp_path / 'plots')) == ['a_run.png', 'b_run.png', 'rheology_vs_phi.png']


# every command-line script (scripts/_fdsusp_path.py is their shim, not a command)
SCRIPTS = sorted(os.path.basename(p) for p in glob.glob(os.path.join(ROOT, 'scripts', '*.py'))
                 if os.path.basename(p) != '_fdsusp_path.py')


def test_every_script_is_listed():
    assert len(SCRIPTS) >= 16 and 'pair_dns.py' in SCRIPTS and 'rheology.py' in SCRIPTS


@pytest.mark.parametrize('script', SCRIPTS)
def test_script_help(script):
    p = subprocess.run([sys.executable, os.path.join(ROOT, 'scripts', script), '--help'],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and p.stdout.startswith('usage:'), p.stderr


def imports(path):
    """The top-level names of the modules a file imports (at any depth: also inside functions),
    and whether it reaches sys.path itself."""
    with open(path) as f:
        tree = ast.parse(f.read(), path)
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.name.split('.')[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            names.add('.' if node.level else node.module.split('.')[0])
    touches_path = any(isinstance(n, ast.Attribute) and n.attr == 'path' and isinstance(n.value, ast.Name)
                       and n.value.id == 'sys' for n in ast.walk(tree))
    return names, touches_path


# what a script may import: the package (through the shim), the standard library and the
# numerical stack (doc/DESIGN.md "The Python package"); never another script. (Python < 3.10 has
# no list of the standard library's modules: there only the scripts are ruled out.)
STDLIB = getattr(sys, 'stdlib_module_names', None)
ALLOWED = None if STDLIB is None else set(STDLIB) | {'fdsusp', '_fdsusp_path', 'numpy', 'h5py', 'matplotlib'}


@pytest.mark.parametrize('script', SCRIPTS)
def test_script_imports_no_script(script):
    siblings = {s[:-3] for s in SCRIPTS}
    names, touches_path = imports(os.path.join(ROOT, 'scripts', script))
    assert not names & siblings, 'imports scripts: %s' % sorted(names & siblings)
    assert ALLOWED is None or names <= ALLOWED, 'imports outside the package, the standard library and numpy/h5py/matplotlib: %s' \
        % sorted(names - ALLOWED)
    assert not touches_path, 'sets sys.path itself (scripts/_fdsusp_path.py is the one shim)'


def test_tests_import_no_script():
    """The tests reach shared code through the package and tests/fdsusp_testlib.py, and find both
    on the PYTHONPATH tests/run_tests.sh sets: no test imports a script or sets sys.path."""
    siblings = {s[:-3] for s in SCRIPTS}
    paths = glob.glob(os.path.join(ROOT, 'tests', '**', '*.py'), recursive=True) + \
        glob.glob(os.path.join(ROOT, 'python', '**', '*.py'), recursive=True)
    assert len(paths) > 40
    bad = []
    for path in paths:
        names, touches_path = imports(path)
        if names & siblings or touches_path:
            bad.append('%s: %s%s' % (os.path.relpath(path, ROOT), sorted(names & siblings),
                                     ' sys.path' if touches_path else ''))
    assert not bad


def test_series_script(tmp_path):
    synthetic(str(tmp_path))
    p = subprocess.run([sys.executable, os.path.join(ROOT, 'scripts', 'series.py'), str(tmp_path)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and '60 records, steps 1..60' in p.stdout
