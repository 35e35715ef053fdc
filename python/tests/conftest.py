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
    """A series file as fdsusp writes one: datasets by path, records along the first axis."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with h5py.File(path, 'w') as f:
        for k, v in (attributes or {}).items():
            f.attrs[k] = v
        for n, v in columns.items():
            f[n] = np.asarray(v)
    return path


@pytest.fixture
def root():
    return ROOT
