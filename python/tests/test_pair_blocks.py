"""fdsusp.pair_blocks, the Python copy of the sized resistance blocks that scripts/calibrate.py
fits the resolved scalars of an unequal pair with. Invariants, each against something the module
does not compute:
  1. Batchelor & Green: two equal spheres (lambda = 1, the exact scalars of bin/fdsusp-resistance)
     free of force and torque in simple shear separate at dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r
     with A, B of bin/fdsusp-resistance shear (mod_pair_mobility, its own solve): to 1e-9
     relative (both solve 12 x 12 systems in double precision from the same series);
  2. exchange: the pair (a2, a1) seen with d reversed is the pair (a1, a2) with its spheres
     swapped (f2 = exchange_sign f(1/lambda) of mod_pair_resistance_unequal), so the forces,
     torques and stresslets of both descriptions agree for any motion and strain: to 1e-12;
  3. folding the M scalars (fold_strain) leaves every stresslet unchanged: to 1e-13 relative.
"""
import numpy as np

from fdsusp import pair_blocks as pb
from fdsusp.resistance import _table

E = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
OMEGA = np.array([0.0, 0.0, -0.5])


def free_velocities(s, a1, a2, d, r):
    """Velocities (U, Om) of both spheres free of force and torque in simple shear, sphere 1 at
    -r d/2, sphere 2 at +r d/2: F = R_FU.(U_inf - U) + R_FE:E = 0 solved column by column."""
    x = np.array([-0.5 * r * d, 0.5 * r * d])
    uinf = np.array([np.concatenate([E @ x[k] + np.cross(OMEGA, x[k]), OMEGA]) for k in range(2)])
    cols = []
    for m in range(12):
        w = np.zeros(12)
        w[m] = 1.0
        F, T, _ = pb.responses(s, a1, a2, d, w.reshape(2, 6), np.zeros((3, 3)))
        cols.append(np.concatenate([F[0], T[0], F[1], T[1]]))
    R = np.array(cols).T
    F, T, _ = pb.responses(s, a1, a2, d, np.zeros((2, 6)), E)
    drive = np.concatenate([F[0], T[0], F[1], T[1]])
    w = np.linalg.solve(R, -drive)        # U_inf - U
    return uinf.ravel() - w


def test_batchelor_green_mobility():
    d = np.array([0.48, 0.6, 0.64])
    d /= np.linalg.norm(d)
    for gap in (0.01, 0.1, 1.0):
        r = 2 + gap
        v = free_velocities(pb.exact_scalars(gap, 1), 1.0, 1.0, d, r)
        rel = v[6:9] - v[0:3]
        A, B = _table('shear', [gap])[0, 1:3]
        er = E @ (r * d)
        expect = np.cross(OMEGA, r * d) + er - (A * np.outer(d, d) + B * (np.eye(3) - np.outer(d, d))) @ er
        assert np.allclose(rel, expect, rtol=1e-9, atol=1e-9 * np.abs(expect).max())


def test_exchange_of_the_spheres():
    rng = np.random.default_rng(7)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    lam, gap = 2.0, 0.05
    s = pb.exact_scalars(gap, lam)
    # the same pair described with the large sphere first: radii (lam, 1), d reversed, scalars
    # of ratio 1/lam, blocks swapped
    s_swapped = s[:, ::-1, ::-1].copy()
    odd = [pb.K[n] for n in ('YB', 'XG', 'YG')]
    s_swapped[odd] *= -1        # odd under d -> -d
    w = rng.normal(size=(2, 6))
    e = rng.normal(size=(3, 3))
    e = 0.5 * (e + e.T) - np.trace(e) / 3 * np.eye(3)
    F, T, S = pb.responses(s, 1.0, lam, d, w, e)
    F2, T2, S2 = pb.responses(s_swapped, lam, 1.0, -d, w[::-1], e)
    for a, b in ((F, F2[::-1]), (T, T2[::-1]), (S, S2[::-1])):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(a).max())


def test_folding_keeps_the_stresslets():
    rng = np.random.default_rng(3)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    s = pb.exact_scalars(0.2, 1.4)
    e = rng.normal(size=(3, 3))
    e = 0.5 * (e + e.T) - np.trace(e) / 3 * np.eye(3)
    _, _, S = pb.responses(s, 1.0, 1.4, d, np.zeros((2, 6)), e)
    _, _, Sf = pb.responses(pb.fold_strain(s, 1.0, 1.4), 1.0, 1.4, d, np.zeros((2, 6)), e)
    assert np.allclose(S, Sf, rtol=1e-13, atol=1e-13 * np.abs(S).max())
