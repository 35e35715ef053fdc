"""The one shim of the scripts: `import _fdsusp_path` (scripts/ is on sys.path when a script runs)
puts this checkout's python/ first on sys.path, so that `import fdsusp` is the package beside these
scripts, not another copy installed elsewhere. With the package installed (`pip install -e .`,
`make install`) and these scripts elsewhere, a script finds it without the shim."""
import os
import sys

_PYTHON = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'python')
if os.path.isdir(os.path.join(_PYTHON, 'fdsusp')) and _PYTHON not in sys.path:
    sys.path.insert(0, _PYTHON)
