"""The pytest suite of the package fdsusp (python/fdsusp), on small synthetic files: run by
`make check` (tests/regression/test_python_package.sh) or `python3 -m pytest python/tests`."""
import os
import sys

import h5py
import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
# the package of this checkout, also when another copy is installed
sys.path.insert(0, os.path.join(ROOT, 'python'))


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
