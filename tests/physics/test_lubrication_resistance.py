"""Invariant: with the full lubrication correction, the hydrodynamic resistance of two spheres and of
a sphere near a wall, as fdsusp computes it at a/Delta = 5 (resolved by the grid + subgrid
correction), equals the exact two-sphere and sphere-wall resistance (mod_pair_resistance,
mod_wall_resistance: Jeffrey & Onishi / Townsend tables for pairs, Brenner 1961 and the O'Neill
bispherical solutions for the wall, each validated against published values by its own unit
tests) within 5 % (issue 5) at gaps 1e-3, 1e-2, 1e-1 and 0.5. The uncorrected DNS (total minus the correction, from the same run)
is printed beside it: it falls short below a gap of about Delta = 0.2a.

Resistance mode (velocities imposed, configuration held), steady state by Aitken extrapolation
of pseudo-time as in scripts/calibrate.py. The configurations are NOT those of the calibration:
another sub-cell offset, another direction of the line of centres, a wall box of another height.
Pairs (periodic 8a cube), relative motions, which exert no net force, so the periodic images act
only as force dipoles, O((a/L)^3) ~ 0.2 %: mode A, the spheres approach at +-d (squeeze) and
sphere 1 spins about d: XA11 - XA12 from F_1, XC11 from T_1; mode B, they slide past each other
at +-e1 and sphere 1 spins about e1: YA11 - YA12 from F_1, YB11 - YB12 from T_1 (the coupling
of sliding to rotation), YC11 from T_1.
Pairs in shear (Couette cell 8 x 10 x 8, shear rate 1, mode C of the calibration): both spheres
move with the undisturbed flow, along a line of centres ds where the strain fit is well
conditioned; the force on sphere 1 is the strain coupling R_FE:E, least-squares fitted to
4 pi [(XG11 - XG12)(ds.E.ds) ds + 2 (YG11 - YG12)(E.ds - (ds.E.ds) ds)] (the sign and form were
checked on the uncorrected runs against the table's G functions, which calibrate.py measures
through the stresslet due to translation: reciprocity holds to ~3 %), and the stresslet gives
the sums XM, YM, ZM (fdsusp.resistance.m_fit). This is the coupling that drives a pair together in a
sheared suspension, and the stresslet its rheology.
Wall (walls at rest, box 8 x 8 x 8): mode W1 translates and spins along the normal (lambda_perp),
W2 along a tangent t (f_tt; f_tr from the torque about b = n x t; f_rr). The cell's other wall and
the images are removed as in scripts/calibrate.py (superposed exact single-wall theory, with
the sphere at the centre as reference).
The resolution is a/Delta = 5 in make check; `test_lubrication_resistance.py N` checks the table of
another resolution N (4, 6, 8: bench, doc/VALIDATION.md §4.2) with the same configurations.
Tolerance 5 %: the issue's. Contributions: the calibration scatter over sub-cell positions and
orientations (doc/LUBRICATION.md table), the Aitken extrapolation (< 0.5 %), the resolved
one-body rotation (XC, YC of an isolated sphere are 1.02, which the pair correction by design
does not touch). Coupling terms (YB11 - YB12, f_tr) are small, so they are held to 5 % of the
largest resistance of their mode.
"""
import math
import os
import sys
import numpy as np
import fdsusp_testlib as T
from fdsusp import resistance as R
from fdsusp.resistance import pair_scalars, wall_scalars, wall_excess, NAMES

PI = math.pi
CELLS = int(sys.argv[1]) if len(sys.argv) > 1 else 5
h = 1.0 / CELLS
GAPS = [0.001, 0.01, 0.1, 0.5]
L = 8.0
work = T.scratch('lubrication_resistance' + ('' if CELLS == 5 else f'_a{CELLS}'))
runner = R.Runner(work, 2)
off = np.array([0.37, 0.61, 0.13]) * h
d = np.array([0.3, -0.5, 0.81]); d /= np.linalg.norm(d)
e1 = np.cross(d, [0.0, 0.0, 1.0]); e1 /= np.linalg.norm(e1)
e2 = np.cross(d, e1)
c = np.full(3, L / 2) + off
zero = np.zeros(3)
add = lambda name, **kw: runner.add(name, h=h, model='full', **kw)
for g in GAPS:
    x1, x2 = c - (1 + g / 2) * d, c + (1 + g / 2) * d
    add(f'g{g}_A', box=(L, L, L), walls=False, shear=0.0, spheres=[(x1, d, d), (x2, -d, zero)])
    add(f'g{g}_B', box=(L, L, L), walls=False, shear=0.0, spheres=[(x1, e1, e1), (x2, -e1, zero)])
n = np.array([0.0, 1.0, 0.0])
t = np.array([math.cos(0.7), 0.0, math.sin(0.7)])
b = np.cross(n, t)
LW = 8.0
for g in GAPS + ['centre']:
    y = LW / 2 if g == 'centre' else 1.0 + g
    x = np.array([L / 2 + off[0], y, L / 2 + off[2]])
    add(f'w{g}_W1', box=(L, LW, L), walls=True, shear=0.0, spheres=[(x, n, n)])
    add(f'w{g}_W2', box=(L, LW, L), walls=True, shear=0.0, spheres=[(x, t, t)])
E = R.SHEAR_E
ds = np.array([0.6, -0.6, 0.53]); ds /= np.linalg.norm(ds)       # conditioning 0.32 (>= 0.25)
LS = 10.0
cs = np.array([L / 2, LS / 2, L / 2]) + off
for g in GAPS:
    x1, x2 = cs - (1 + g / 2) * ds, cs + (1 + g / 2) * ds
    add(f'g{g}_S', box=(L, LS, L), walls=True, shear=1.0, spheres=[R.with_flow(x1, LS), R.with_flow(x2, LS)])
runner.run()


def steady(name):
    """Total and lubrication force/torque, extrapolated to steady state."""
    return R.steady_with_lubrication(os.path.join(work, name))


print('a/Delta = %d' % CELLS)
print('%7s %-9s %9s %9s %9s %7s' % ('gap', 'function', 'exact', 'fdsusp', 'no corr.', 'error'))
for g in GAPS:
    ex = dict(zip(NAMES, pair_scalars(g)))
    exs = {'XA11-XA12': ex['XA11'] - ex['XA12'], 'XC11': ex['XC11'], 'YA11-YA12': ex['YA11'] - ex['YA12'],
           'YB11-YB12': ex['YB11'] - ex['YB12'], 'YC11': ex['YC11']}
    dns, raw = {}, {}
    F, Tq, Fl, Tl = steady(f'g{g}_A')
    for out, (f1, t1) in ((dns, (F[0], Tq[0])), (raw, (F[0] - Fl[0], Tq[0] - Tl[0]))):
        out['XA11-XA12'] = -f1 @ d / (6 * PI)
        out['XC11'] = -t1 @ d / (8 * PI)
    F, Tq, Fl, Tl = steady(f'g{g}_B')
    for out, (f1, t1) in ((dns, (F[0], Tq[0])), (raw, (F[0] - Fl[0], Tq[0] - Tl[0]))):
        out['YA11-YA12'] = -f1 @ e1 / (6 * PI)
        out['YB11-YB12'] = t1 @ e2 / (4 * PI)
        out['YC11'] = -t1 @ e1 / (8 * PI)
    for k in exs:
        scale = abs(exs[k]) if k != 'YB11-YB12' else max(abs(exs['YA11-YA12']), abs(exs['YC11']))
        err = (dns[k] - exs[k]) / scale
        print('%7g %-9s %9.4f %9.4f %9.4f %+7.2f%%' % (g, k, exs[k], dns[k], raw[k], 100 * err))
        T.check(abs(err) <= 0.05, 'pair gap %g: %s within 5 %% of exact (%.2f %%)' % (g, k, 100 * err))
    # in shear: G functions from the force on sphere 1, M sums from the stresslets. The small
    # couplings (YG; YM, ZM) are held to 5 % of the largest function of their kind (XG; XM).
    ded = ds @ E @ ds
    basis = 4 * PI * np.array([ded * ds, 2 * (E @ ds - ded * ds)]).T
    F, Tq, Fl, Tl = steady(f'g{g}_S')
    g_dns = np.linalg.lstsq(basis, F[0], rcond=None)[0]
    g_raw = np.linalg.lstsq(basis, F[0] - Fl[0], rcond=None)[0]
    S = R.steady(os.path.join(work, f'g{g}_S'))[2]       # deviatoric stresslets
    m_dns = 0.5 * (R.m_fit(S[0], ds, E) + R.m_fit(S[1], ds, E))
    values = [('XG11-XG12', ex['XG11'] - ex['XG12'], g_dns[0], g_raw[0], None),
              ('YG11-YG12', ex['YG11'] - ex['YG12'], g_dns[1], g_raw[1], ex['XG11'] - ex['XG12'])]
    values += [(m, ex[m + '11'] + ex[m + '12'], m_dns[k], float('nan'), None if k == 0 else ex['XM11'] + ex['XM12'])
               for k, m in enumerate(('XM', 'YM', 'ZM'))]
    for k, exact, dns_k, raw_k, largest in values:
        err = (dns_k - exact) / abs(exact if largest is None else largest)
        print('%7g %-9s %9.4f %9.4f %9.4f %+7.2f%%' % (g, k, exact, dns_k, raw_k, 100 * err))
        T.check(abs(err) <= 0.05, 'pair in shear gap %g: %s within 5 %% of exact (%.2f %%)' % (g, k, 100 * err))


def wall_values(tag, total=True):
    F, Tq, Fl, Tl = steady(f'w{tag}_W1')
    if not total:
        F, Tq = F - Fl, Tq - Tl
    lam = -F[0] @ n / (6 * PI)
    F, Tq, Fl, Tl = steady(f'w{tag}_W2')
    if not total:
        F, Tq = F - Fl, Tq - Tl
    return np.array([lam, -F[0] @ t / (6 * PI), Tq[0] @ b / (6 * PI), -Tq[0] @ t / (8 * PI)])

centre = wall_values('centre')
mid = 2.0 * wall_excess(LW / 2 - 1.0)[:4]
for g in GAPS:
    far = wall_excess(LW - 2.0 - g)[:4]
    dns = wall_values(g) - centre - far + mid + np.array([1.0, 1.0, 0.0, 1.0])
    raw = wall_values(g, total=False) - centre - far + mid + np.array([1.0, 1.0, 0.0, 1.0])
    ex = wall_scalars(g)
    for k, name in enumerate(('lambda_perp', 'f_tt', 'f_tr', 'f_rr')):
        scale = abs(ex[k]) if name != 'f_tr' else max(abs(ex[1]), abs(ex[3]))
        err = (dns[k] - ex[k]) / scale
        print('%7g %-11s %9.4f %9.4f %9.4f %+7.2f%%' % (g, name, ex[k], dns[k], raw[k], 100 * err))
        T.check(abs(err) <= 0.05, 'wall gap %g: %s within 5 %% of exact (%.2f %%)' % (g, name, 100 * err))
T.finish()
