"""The exact resistance functions of mod_pair_resistance, mod_wall_resistance and mod_pair_mobility, from bin/fdsusp-resistance (doc/RESISTANCE.md)."""
import os
import subprocess
import numpy as np
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp.run import program  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAMES = ["XA11", "YA11", "YB11", "XC11", "YC11", "XG11", "YG11", "YH11", "XM11", "YM11", "ZM11",
         "XA12", "YA12", "YB12", "XC12", "YC12", "XG12", "YG12", "YH12", "XM12", "YM12", "ZM12"]


def _table(kind, gaps):
    out = subprocess.run([program('fdsusp-resistance'), kind] + ['%.17g' % g for g in gaps],
                         check=True, capture_output=True, text=True).stdout
    return np.array([[float(v) for v in line.split()] for line in out.splitlines() if not line.startswith('#')])


def pair_scalars(gap):
    """The 22 equal-sphere scalars at this gap, in the order of NAMES."""
    return _table('pair', [gap])[0, 1:]


def shear_functions(gaps):
    """Rows [A, B, C, K, L, M] of a force- and torque-free equal pair in a linear flow at these gaps
    (Batchelor & Green; mod_pair_mobility::pair_shear_functions): the relative velocity is
    dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r."""
    return _table('shear', list(gaps))[:, 1:]


def wall_scalars(gap):
    """[lambda_perp, f_tt, f_tr, f_rr, x_w] at this gap."""
    return _table('wall', [gap])[0, 1:]


FREE_SPHERE_WALL = np.array([1.0, 1.0, 0.0, 1.0, 1.0])


def wall_excess(gap):
    """What one wall adds to the free-sphere values: wall_scalars(gap) - [1, 1, 0, 1, 1]."""
    return wall_scalars(gap) - FREE_SPHERE_WALL
