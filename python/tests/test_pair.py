"""fdsusp.pair.branch and fdsusp.series.consolidate: a case of the pair study started from the
trunk's output holds one consistent series (series.h5 alone, up to the checkpoint, the case's
columns), also when the trunk left records in series.parts/ (doc/DESIGN.md "series.h5: immutable
parts, atomic consolidation"); and fdsusp continues such a branch."""
import os

import h5py
import numpy as np
import pytest

from conftest import write_series
from fdsusp import deck, pair, run, series

CONTACT = ('particles/force_contact', 'particles/stresslet_contact')


def columns(steps):
    steps = np.asarray(steps, dtype=np.int32)
    n = len(steps)
    return {'step': steps, 'time': 1e-3 * steps,
            'particles/position': np.arange(n * 6, dtype=float).reshape(n, 2, 3),
            'particles/force_contact': np.zeros((n, 2, 3)),
            'particles/stresslet_contact': np.ones((n, 2, 3, 3))}


def trunk_with_parts(root):
    """A trunk killed after its checkpoint at step 80: series.h5 to step 50, a stale part (its
    records already in series.h5: a kill between publishing and removing), parts to step 90."""
    out = os.path.join(root, 'trunk', 'out')
    write_series(os.path.join(out, 'series.h5'), columns([10, 20, 30, 40, 50]), {'dt': 1e-3, 'shear_rate': 1.0})
    for first, steps in ((40, [40, 50]), (60, [60, 70]), (80, [80, 90])):
        write_series(os.path.join(out, 'series.parts', '%010d.h5' % first), columns(steps))
    with h5py.File(os.path.join(out, 'checkpoint.h5'), 'w') as f:
        f.attrs['step'] = np.array([80], dtype=np.int32)
    return os.path.dirname(out)


@pytest.mark.parametrize('case', ['eps0', 'eps1e-2'])
def test_branch_folds_the_parts(tmp_path, case):
    trunk = trunk_with_parts(str(tmp_path))
    before = series.read(os.path.join(trunk, 'out'))[0]
    d = str(tmp_path / case)
    pair.branch(trunk, d, case)
    out = os.path.join(d, 'out')
    assert series.files(out) == [os.path.join(out, 'series.h5')]          # no part left beside it
    assert not os.path.exists(os.path.join(out, 'series.h5.tmp'))
    cols, attrs = series.read(out)                                       # every column, one file
    assert list(cols['step']) == [10, 20, 30, 40, 50, 60, 70, 80]         # up to the checkpoint
    smooth = case == 'eps0'
    assert sorted(cols) == sorted(n for n in before if not (smooth and n in CONTACT))
    for n, v in cols.items():
        assert np.array_equal(v, before[n][:8]), n
    assert float(attrs['shear_rate']) == 1.0
    with h5py.File(os.path.join(out, 'series.h5'), 'r') as f:
        # fdsusp appends to these columns when the case continues
        assert f['step'].dtype == np.int32 and f['step'].maxshape == (None,)
        assert f['particles/position'].maxshape == (None, 2, 3) and f['particles/position'].chunks is not None
    # the trunk is left as it was
    assert series.pending_parts(os.path.join(trunk, 'out')) == 3
    assert list(series.read(os.path.join(trunk, 'out'), ['step'])[0]['step'])[-1] == 90


def test_consolidate_without_series_h5(tmp_path):
    """Parts alone (a run killed before its first consolidation) make a series.h5."""
    out = str(tmp_path)
    write_series(os.path.join(out, 'series.parts', '%010d.h5' % 1), columns([1, 2]))
    write_series(os.path.join(out, 'series.parts', '%010d.h5' % 3), columns([3]))
    assert series.consolidate(out) == 3
    assert series.files(out) == [os.path.join(out, 'series.h5')]
    assert list(series.read(out, ['step'])[0]['step']) == [1, 2, 3]


def test_fdsusp_continues_a_branch_with_parts(tmp_path, fdsusp_binary):
    """The trunk run by fdsusp (its series split into series.h5 and parts as a kill leaves it),
    branched and continued by fdsusp from the checkpoint: the continuation keeps every record,
    warns of nothing and sets nothing aside. The trunk's own case continues with -restart; cases
    of other contact physics (friction, smooth spheres without &contact) with -branch, which takes
    their deck's contact model (a -restart refuses it: src/io/restart_deck.F90), as
    pair.prepare(branched=True) runs them."""
    binary = fdsusp_binary
    dt, steps = 2.5e-3, 24         # a record every 4 steps (pair.record_every), a checkpoint every 2

    def write(d, case, n, contact):
        os.makedirs(d, exist_ok=True)
        deck.write(os.path.join(d, 'deck.nml'), pair.dns_deck(case, 8.0, 4, 0.01, 0.5, dt, n, 0.0, 2.7, 3.9, 5.3, 4.1,
                                                              4.0, contact))

    contact = {'roughness': 1e-2, 'eps_bar': 0.1, 'friction': 0.0}
    trunk = str(tmp_path / 'trunk')
    write(trunk, pair.TRUNK_CASE, steps, contact)
    p = run.run('deck.nml', cwd=trunk, binary=binary, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    out = os.path.join(trunk, 'out')
    whole = series.read(out)[0]
    assert 'particles/force_contact' in whole
    # as a kill leaves it: series.h5 to step 12, the later records in two parts
    later = whole['step'] > 12
    series.consolidate(out, last_step=12)
    for first in (16, 24):
        sel = later & (whole['step'] >= first) & (whole['step'] < first + 8)
        write_series(os.path.join(out, 'series.parts', '%010d.h5' % first), {n: v[sel] for n, v in whole.items()})
    assert series.pending_parts(out) == 2

    d = str(tmp_path / pair.TRUNK_CASE)
    pair.branch(trunk, d, pair.TRUNK_CASE)
    write(d, pair.TRUNK_CASE, 2 * steps, contact)
    p = run.run('deck.nml', cwd=d, binary=binary, args=['-restart', 'out/checkpoint.h5'], timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    # the series' warnings name the file they set aside (src/io/series.F90 keep_aside)
    warned = [l for l in (p.stdout + p.stderr).splitlines() if 'warning' in l and 'series' in l]
    assert not warned
    out = os.path.join(d, 'out')
    aside = [n for n in os.listdir(out) + os.listdir(os.path.join(out, 'series.parts'))
             if '.other-columns' in n or '.damaged' in n]
    assert not aside
    cols = series.read(out)[0]
    assert sorted(cols) == sorted(whole)
    assert list(cols['step']) == list(range(4, 2 * steps + 1, 4))
    # the branch's records are the trunk's up to its checkpoint, bit for bit
    k = len(whole['step'])
    assert np.array_equal(cols['particles/position'][:k], whole['particles/position'])

    # cases of other contact physics branch from the same trunk
    for case, other in (('eps1e-2_mu03', dict(contact, friction=0.3)), ('eps0', None)):
        d = str(tmp_path / case)
        pair.branch(trunk, d, case)
        write(d, case, 2 * steps, other)
        p = run.run('deck.nml', cwd=d, binary=binary, args=['-restart', 'out/checkpoint.h5'], timeout=300)
        assert p.returncode == 2 and 'or branch from the checkpoint' in p.stderr
        p = run.run('deck.nml', cwd=d, binary=binary, args=['-branch', 'out/checkpoint.h5'], timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        log = p.stdout.splitlines()
        if other:
            assert any(l.startswith('branch: &contact changed from friction = 0 to friction = 3.0E-01') for l in log)
        else:
            assert any(l.startswith("branch: the checkpoint's run had contacts, this one has none") for l in log)
        cols = series.read(os.path.join(d, 'out'))[0]
        assert list(cols['step']) == list(range(4, 2 * steps + 1, 4))
        assert np.array_equal(cols['particles/position'][:k], whole['particles/position'])
