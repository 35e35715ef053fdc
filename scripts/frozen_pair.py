#!/usr/bin/env python3
"""The steady free mobility of a pair in shear (doc/VALIDATION.md §4.4): two spheres frozen in a
10a Couette cube (motion 'frozen': force- and torque-free velocities at a fixed configuration,
pseudo-time to the steady state by Aitken), full lubrication correction, at each resolution given
and gaps 0.01, 0.1, 0.3, against the exact relative velocity of a free pair,
    dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r   (Batchelor & Green; bin/fdsusp-resistance shear).
Printed: the radial part as 1 - A (what a trajectory integrates: near contact it is small and
sensitive, 2.7 times the relative error of XG/XA at gap 0.1, 25 times at 0.01) and the tangential
part as 1 - B, each against exact. The 10a cube confines the pair by ~1-2 % in 1 - A (an 8a box by
16 % at gap 0.03; measured at a/Delta 4 against a 20a cube, VALIDATION §4.4).
    scripts/frozen_pair.py 4,5,6      (work in out/frozen_pair; ~5 min on 2 cores)"""
import argparse
import os

import numpy as np

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp import resistance as R, series

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument('cells', help='the resolutions a/Delta, comma-separated (e.g. 4,5,6)')
args = ap.parse_args()

GAPS = [0.01, 0.1, 0.3]
L = 10.0
d = np.array([0.6, -0.6, 0.53]); d /= np.linalg.norm(d)     # d.E.d and the tangential E.d both nonzero
cells = [int(c) for c in args.cells.split(',')]
work = os.path.join(ROOT, 'out', 'frozen_pair')
os.makedirs(work, exist_ok=True)
runner = R.Runner(work, 2)
for n in cells:
    centre = np.full(3, L / 2) + np.array([0.29, 0.71, 0.43]) / n
    for g in GAPS:
        runner.add(f'a{n}_g{g}', box=(L, L, L), walls=True, shear=1.0, h=1.0 / n, model='full', motion='frozen',
                   spheres=[R.with_flow(centre + s * (1 + g / 2) * d, L) for s in (-1, 1)])
runner.run()
Ed = R.SHEAR_E @ d
ded = d @ Ed
t = Ed - ded * d
t /= np.linalg.norm(t)
exact = dict(zip(GAPS, R.shear_functions(GAPS)))
print('| a/Delta | gap | 1 - A exact | DNS | error | 1 - B exact | DNS | error |')
print('|---|---|---|---|---|---|---|---|')
for n in cells:
    for g in GAPS:
        V = R.aitken(series.read(os.path.join(work, f'a{n}_g{g}'), ['particles/velocity'])[0]['particles/velocity'])
        dv = V[1] - V[0]                       # dr/dt; Om x r has no radial part, its t part is removed
        s = 2 + g
        one_a = (dv @ d) / (s * ded)
        one_b = (dv @ t - s * np.cross(R.SHEAR_OMEGA, d) @ t) / (s * (Ed @ t))
        ea, eb = 1 - exact[g][0], 1 - exact[g][1]
        print(f'| {n} | {g} | {ea:.5f} | {one_a:.5f} | {100 * (one_a / ea - 1):+.1f} % | {eb:.4f} | {one_b:.4f} | '
              f'{100 * (one_b / eb - 1):+.2f} % |')
