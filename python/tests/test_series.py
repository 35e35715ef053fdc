"""fdsusp.series: series.h5 and series.parts/ merged as fdsusp consolidates them."""
import os

import numpy as np
import pytest

from conftest import write_series
from fdsusp import series


def records(steps):
    steps = np.asarray(steps)
    return {'step': steps, 'time': 0.1 * steps, 'particles/velocity': np.stack([steps, -steps], axis=1) * 1.0}


def test_series_h5_alone(tmp_path):
    write_series(str(tmp_path / 'series.h5'), records([1, 2, 3]), {'shear_rate': 2.0})
    cols, attrs = series.read(str(tmp_path))
    assert list(cols['step']) == [1, 2, 3]
    assert cols['particles/velocity'].shape == (3, 2)
    assert float(attrs['shear_rate']) == 2.0
    assert series.pending_parts(str(tmp_path)) == 0


def test_parts_merged_after_last_step_in_name_order(tmp_path):
    d = str(tmp_path)
    write_series(os.path.join(d, 'series.h5'), records([1, 2, 3, 4]), {'dt': 0.1})
    # parts in name order; records at or before the last step so far are dropped (a part written
    # before a consolidation that a continuation cut back)
    write_series(os.path.join(d, 'series.parts', 'part_000002.h5'), records([7, 8]))
    write_series(os.path.join(d, 'series.parts', 'part_000001.h5'), records([3, 4, 5, 6]))
    write_series(os.path.join(d, 'series.parts', 'part_000003.h5'), records([5, 6, 7, 8, 9]))
    write_series(os.path.join(d, 'series.parts', '.part_000004.h5'), records([100]))   # being written
    cols, attrs = series.read(d)
    assert list(cols['step']) == [1, 2, 3, 4, 5, 6, 7, 8, 9]
    assert np.allclose(cols['time'], 0.1 * np.arange(1, 10))
    assert np.array_equal(cols['particles/velocity'][:, 1], -np.arange(1, 10))
    assert float(attrs['dt']) == 0.1
    assert series.pending_parts(d) == 4      # as scripts/series.py has always counted: every *.h5
    assert [os.path.basename(p) for p in series.files(d)] == ['series.h5', 'part_000001.h5',
                                                              'part_000002.h5', 'part_000003.h5']


def test_parts_alone_and_names(tmp_path):
    d = str(tmp_path)
    write_series(os.path.join(d, 'series.parts', 'part_000001.h5'), records([1, 2]), {'dt': 0.5})
    write_series(os.path.join(d, 'series.parts', 'part_000002.h5'), records([3]))
    cols, attrs = series.read(d, ['time'])
    assert list(cols) == ['time']              # 'step' used for the merge, not returned
    assert np.allclose(cols['time'], [0.1, 0.2, 0.3])
    assert float(attrs['dt']) == 0.5
    cols, _ = series.read(d, ['step', 'time'])
    assert list(cols) == ['step', 'time']


def test_empty_part_keeps_last_step(tmp_path):
    d = str(tmp_path)
    write_series(os.path.join(d, 'series.h5'), records([1, 2]))
    write_series(os.path.join(d, 'series.parts', 'a.h5'), records([2]))   # nothing new
    write_series(os.path.join(d, 'series.parts', 'b.h5'), records([2, 3]))
    assert list(series.read(d)[0]['step']) == [1, 2, 3]


def test_missing(tmp_path):
    with pytest.raises(FileNotFoundError):
        series.read(str(tmp_path))
    write_series(str(tmp_path / 'series.h5'), records([1]))
    with pytest.raises(KeyError):
        series.read(str(tmp_path), ['core/stress_hydro'])


def test_describe_and_settings(tmp_path):
    write_series(str(tmp_path / 'series.h5'), records([5, 10]), {'dt': np.array([0.25]), 'blocks': 5})
    lines = series.describe(str(tmp_path))
    assert lines[0].endswith('2 records, steps 5..10, 0 part(s) not yet in series.h5')
    assert any(l.split()[0] == 'particles/velocity' and l.endswith('(2, 2)') for l in lines[1:])
    assert series.settings(series.read(str(tmp_path))[1]) == {'dt': 0.25, 'blocks': 5.0}
    assert sorted(series.names(str(tmp_path))) == ['particles/velocity', 'step', 'time']
