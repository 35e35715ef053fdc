"""fdsusp.plots draws its figures; the command-line scripts answer --help."""
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
    runs = []
    for name in ('a', 'b'):
        d = synthetic(str(tmp_path / name / 'out'))
        a, s = rheology.load(d)
        runs.append((d, a, s, rheology.summarise(a, s)))
    plots.run_figures(runs, str(tmp_path / 'plots'))
    assert sorted(os.listdir(tmp_path / 'plots')) == ['a_run.png', 'b_run.png', 'rheology_vs_phi.png']


SCRIPTS = ['rheology.py', 'series.py', 'friction_study.py', 'model_trade.py']


@pytest.mark.parametrize('script', SCRIPTS)
def test_script_help(script):
    p = subprocess.run([sys.executable, os.path.join(ROOT, 'scripts', script), '--help'],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and p.stdout.startswith('usage:'), p.stderr


def test_series_script(tmp_path):
    synthetic(str(tmp_path))
    p = subprocess.run([sys.executable, os.path.join(ROOT, 'scripts', 'series.py'), str(tmp_path)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and '60 records, steps 1..60' in p.stdout
