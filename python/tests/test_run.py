"""fdsusp.run: where the programs are, the command lines, the job pool."""
import os
import subprocess
import sys

from fdsusp import run


def test_checkout_and_env(monkeypatch, root):
    monkeypatch.delenv('FDSUSP_BIN', raising=False)
    assert run.checkout() == root
    assert run.bin_dir() == os.path.join(root, 'bin')
    assert run.program('pairtraj') == os.path.join(root, 'bin', 'pairtraj')
    monkeypatch.setenv('FDSUSP_BIN', '/opt/pinned/bin')
    assert run.program() == '/opt/pinned/bin/fdsusp'


def test_command():
    assert run.command('d.nml', binary='/x/fdsusp') == ['/x/fdsusp', 'd.nml']
    assert run.command('d.nml', 3, ['-restart', 'c.h5'], binary='/x/fdsusp') == \
        ['mpiexec', '--oversubscribe', '-n', '3', '/x/fdsusp', 'd.nml', '-restart', 'c.h5']
    assert run.ENV['OMPI_ALLOW_RUN_AS_ROOT'] == '1'


def test_run_all_collects_each_case():
    reported = []

    def start(case):
        return subprocess.Popen([sys.executable, '-c', 'import sys; sys.exit(%d)' % case])

    results = run.run_all([0, 3, 5, 0], lambda c: start(c), jobs=2,
                          report=lambda c, status, cpu: reported.append((c, status)))
    assert {c: s for c, (s, _) in results.items()} == {0: 0, 3: 3, 5: 5}
    assert sorted(reported) == [(0, 0), (0, 0), (3, 3), (5, 5)]
    assert all(cpu >= 0 for _, cpu in results.values())


def test_start_resumable(tmp_path, monkeypatch):
    # a stand-in program: prints its arguments
    fake = tmp_path / 'bin' / 'fdsusp'
    fake.parent.mkdir()
    fake.write_text('#!/bin/sh\necho "args: $*"\n')
    fake.chmod(0o755)
    monkeypatch.setenv('FDSUSP_BIN', str(fake.parent))
    d = str(tmp_path / 'case')
    proc, fresh = run.start_resumable(d, '&time dt = 1 /\n')
    assert fresh and proc.wait() == 0
    os.makedirs(os.path.join(d, 'out'))
    open(os.path.join(d, 'out', 'checkpoint.h5'), 'w').close()
    proc, fresh = run.start_resumable(d, '&time dt = 2 /\n')
    assert not fresh and proc.wait() == 0
    log = open(os.path.join(d, 'log')).read()
    assert 'args: deck.nml\n' in log and 'args: deck.nml -restart out/checkpoint.h5' in log
    assert open(os.path.join(d, 'deck.nml')).read() == '&time dt = 2 /\n'


def test_pinned_build_names_its_commit(tmp_path, monkeypatch):
    """A study records the VERSION beside the programs fdsusp.run finds ($FDSUSP_BIN here)."""
    from fdsusp import study
    (tmp_path / 'VERSION').write_text('abc1234\n')
    monkeypatch.setenv('FDSUSP_BIN', str(tmp_path))
    assert study.commit_of_binary() == 'abc1234'
