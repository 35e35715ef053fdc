"""Far-field (reflection) forms of the sphere-wall resistance functions, x = a/l with l the centre
height (method.md §2.8; the same forms as mod_resistance's wall_normal_far_field and
wall_tangential_far; twist: Jeffery 1915, X_w = 1 + x^3/8 + O(x^6)). Accurate to < 1e-3 for
l >= 4a, which is all scripts/calibrate.py uses them for (the far walls of its cell)."""
import numpy as np


def wall_functions(gap):
    """[lambda_perp, f_tt, f_tr, f_rr, x_w] at gap = l/a - 1 (a = 1)."""
    x = 1.0 / (1.0 + gap)
    lam = 1.0 / (1.0 - 1.125 * x + 0.5 * x**3 - 0.57 * x**4 + 0.2 * x**5)
    ftt = 1.0 / (1.0 - 9.0 / 16 * x + x**3 / 8 - 45.0 / 256 * x**4 - x**5 / 16)
    ftr = x**4 / 8 * (1.0 - 3.0 / 8 * x)
    frr = 1.0 + 5.0 / 16 * x**3
    xw = 1.0 + x**3 / 8
    return np.array([lam, ftt, ftr, frr, xw])
