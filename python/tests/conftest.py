"""The pytest suite of the package fdsusp (python/fdsusp), on small synthetic files: run by
`make check` (tests/regression/test_python_package.sh) or `python3 -m pytest python/tests`. The
package imported is this checkout's, also when another copy is installed: pyproject.toml's
[tool.pytest.ini_options] pythonpath puts python/ first."""
import os

import h5py
import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def write_series(path, columns, attributes=None):
    """A series file as fdsusp writes one: datasets by path, records along the first axis, which
    can grow (src/io/series.F90 create_column: a continuing run appends to them)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with h5py.File(path, 'w') as f:
        for k, v in (attributes or {}).items():
            f.attrs[k] = v
        for n, v in columns.items():
            v = np.asarray(v)
            f.create_dataset(n, data=v, maxshape=(None,) + v.shape[1:], chunks=True)
    return path


@pytest.fixture
def root():
    return ROOT


@pytest.fixture
def fdsusp_binary():
    """bin/fdsusp as fdsusp.run finds it; the test is skipped when it is not built."""
    from fdsusp import run
    try:
        path = run.program('fdsusp')
    except FileNotFoundError:
        path = None
    if path is None or not os.access(path, os.X_OK):
        pytest.skip('bin/fdsusp is not built')
    return path
