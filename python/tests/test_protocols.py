"""fdsusp.protocols on synthetic series whose answers are known (doc/RHEOLOGY.md "Protocols")."""
import math
import os

import numpy as np
import pytest

from conftest import write_series
from fdsusp import protocols

DT = 0.01


def oscillation(outdir, g1=(0.3, 2.0), g3=(0.05, -0.02), periods=3, steps=100):
    """An oscillation gamma_0 = 0.1, T = steps dt: particle shear stress gamma_0 (G'_h sin + G''_h
    cos)(h omega t_n) for h = 1, 3, minus the solvent's gamma_dot, so that the total is exactly that;
    positions that move by (0.01 k) a in x per cycle k, one sphere across the sliding boundary."""
    gamma_0, period = 0.1, steps * DT
    omega = 2 * math.pi / period
    n = periods * steps
    step = np.arange(1, n + 1)
    t_n = (step - 1) * DT
    rate = gamma_0 * omega * np.cos(omega * t_n)
    total = gamma_0 * (g1[0] * np.sin(omega * t_n) + g1[1] * np.cos(omega * t_n)
                       + g3[0] * np.sin(3 * omega * t_n) + g3[1] * np.cos(3 * omega * t_n))
    sh = np.zeros((n, 5))
    sh[:, 3] = total - rate
    x = np.zeros((n, 2, 3))
    cycle = step // steps
    x[:, 0] = np.stack([1.0 + 0.01 * cycle, np.full(n, 5.0), np.full(n, 5.0)], axis=1)
    # sphere 2 drifts up by 0.2 a per cycle from y = 9.7: it crosses y = Ly = 10 after 2 cycles
    x[:, 1] = np.stack([np.full(n, 3.0), 9.7 + 0.2 * step / steps, np.full(n, 5.0)], axis=1)
    wrapped = x[:, 1, 1] >= 10.0
    offset = np.full(n, 0.5)
    x[wrapped, 1, 1] -= 10.0
    x[wrapped, 1, 0] -= offset[wrapped]
    cols = {'step': step, 'time': step * DT, 'shear/rate': rate, 'shear/strain': gamma_0 * np.sin(omega * t_n),
            'core/stress_hydro': sh, 'core/stress_contact': np.zeros((n, 5)), 'particles/position': x,
            'lees_edwards_offset': offset}
    attrs = dict(shear_protocol=3.0, shear_reference_rate=gamma_0 * omega, shear_reversal_strain=0.0,
                 shear_strain_amplitude=gamma_0, shear_period=period, shear_dt=DT)
    write_series(os.path.join(outdir, 'series.h5'), cols, attrs)
    return outdir


def test_moduli(tmp_path):
    m = protocols.oscillation_moduli(oscillation(str(tmp_path)))
    assert m['periods'] == [0, 1, 2]
    assert m[1]["G'"][0] == pytest.approx(0.3, abs=1e-10) and m[1]["G''"][0] == pytest.approx(2.0, abs=1e-10)
    assert m[3]["G'"][0] == pytest.approx(0.05, abs=1e-10) and m[3]["G''"][0] == pytest.approx(-0.02, abs=1e-10)
    assert m[1]["G'"][1] == pytest.approx(0.0, abs=1e-10)


def test_stroboscopic(tmp_path):
    d = protocols.stroboscopic_msd(oscillation(str(tmp_path)), [10.0, 10.0, 10.0], threshold=0.1)
    assert list(d['cycles']) == [1, 2, 3]
    # sphere 1 moves 0.01 a per cycle, sphere 2 0.2 a (across the boundary between cycles 2 and 3)
    assert d['msd'] == pytest.approx([(0.01 ** 2 + 0.2 ** 2) / 2] * 2, rel=1e-9)
    assert list(d['moved']) == [0.5, 0.5]


def reversal_columns():
    """Rate +1 for 50 steps, then -1, +1, -1 (G = 0.5): the contact shear stress relaxes to 0 after
    each reversal and rises as c = strain since reversal (signed with the direction); N1 = 2 c."""
    n = 200
    step = np.arange(1, n + 1)
    k = step - 1
    rate = np.where((k // 50) % 2 == 0, 1.0, -1.0)
    since = (k % 50) * DT
    strain = np.where((k // 50) % 2 == 0, since, 0.5 - since)
    sc = np.zeros((n, 5))
    sc[:, 3] = since * rate
    sc[:, 0] = 2 * since
    cols = {'step': step, 'time': step * DT, 'shear/rate': rate, 'shear/strain': strain,
            'core/stress_hydro': np.zeros((n, 5)), 'core/stress_contact': sc}
    attrs = dict(shear_protocol=2.0, shear_reference_rate=1.0, shear_reversal_strain=0.5,
                 shear_strain_amplitude=0.0, shear_period=0.0, shear_dt=DT)
    return cols, attrs


def test_reversal(tmp_path):
    cols, attrs = reversal_columns()
    write_series(os.path.join(str(tmp_path), 'series.h5'), cols, attrs)
    r = protocols.reversal_transient(str(tmp_path))
    assert list(r['reversal_steps']) == [51, 101, 151] and list(r['count']) == [3] * 50
    assert r['strain'] == pytest.approx(np.arange(50) * DT)
    assert r['shear_c']['mean'] == pytest.approx(np.arange(50) * DT)
    assert r['N1_c']['mean'] == pytest.approx(2 * np.arange(50) * DT)
    assert r['shear_c']['error'] == pytest.approx(np.zeros(50), abs=1e-12)
    assert r['shear_h']['mean'] == pytest.approx(np.ones(50))        # the solvent: |rate| = 1


def test_reversal_sparse_records(tmp_path):
    """Every 5th record from the 4th (series_every 5, no record on a reversal step): the strain
    since reversal counts from the turning point (3 steps before the first record after it), not
    from that record."""
    cols, attrs = reversal_columns()
    sparse = {k: v[3::5] for k, v in cols.items()}
    write_series(os.path.join(str(tmp_path), 'series.h5'), sparse, attrs)
    r = protocols.reversal_transient(str(tmp_path))
    assert list(r['reversal_steps']) == [54, 104, 154] and list(r['count']) == [3] * 10
    assert r['turning_strain'] == pytest.approx([0.5, 0.0, 0.5], abs=1e-12)
    expected = 0.03 + 0.05 * np.arange(10)
    assert r['strain'] == pytest.approx(expected)
    assert r['shear_c']['mean'] == pytest.approx(expected)
    assert r['N1_c']['mean'] == pytest.approx(2 * expected)


def test_steady_has_no_protocol(tmp_path):
    write_series(os.path.join(str(tmp_path), 'series.h5'), {'step': np.arange(1, 4), 'shear/rate': np.ones(3)}, {})
    with pytest.raises(protocols.NoProtocol):
        protocols.settings(str(tmp_path))
