#!/usr/bin/env python3
"""The steady free mobility of a pair in shear (doc/VALIDATION.md §4.4): two spheres frozen in the
8 x 10 x 8 Couette cell (motion 'frozen': force- and torque-free velocities at a fixed
configuration, pseudo-time to the steady state by Aitken), full lubrication correction, at each
resolution given and gaps 0.01, 0.1, 0.3. Prints the radial velocity of each sphere relative to
the undisturbed flow against the exact two-sphere value: force-free along the line of centres d,
-6 pi (XA11 - XA12) (U1 - U_inf).d + 4 pi (XG11 - XG12) d.E.d = 0 (equal spheres: the squeeze
decouples from rotation and sliding), i.e. (U1 - U_inf).d = (2/3)(XG11 - XG12)/(XA11 - XA12) d.E.d.
    scripts/frozen_pair.py 4,5,6      (work in out/frozen_check; ~2 min on 2 cores)"""
import os
import sys
import h5py
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calibrate as C
from resistance_exact import pair_scalars, NAMES

I = {n: k for k, n in enumerate(NAMES)}
GAPS = [0.01, 0.1, 0.3]
L, LW = 8.0, 10.0
d = np.array([0.6, -0.6, 0.53]); d /= np.linalg.norm(d)
cells = [int(c) for c in sys.argv[1].split(',')]
work = os.path.join(C.ROOT, 'out', 'frozen_check')
os.makedirs(work, exist_ok=True)
runner = C.Runner(work, 2)
pairs = {}
for n in cells:
    centre = np.array([L / 2, LW / 2, L / 2]) + np.array([0.29, 0.71, 0.43]) / n
    for g in GAPS:
        pairs[n, g] = [C.with_flow(centre + s * (1 + g / 2) * d, LW) for s in (-1, 1)]
        runner.add(f'a{n}_g{g}', box=(L, LW, L), walls=True, shear=1.0, spheres=pairs[n, g], h=1.0 / n,
                   model='full', motion='frozen')
runner.run()
ded = d @ C.SHEAR_E @ d
for (n, g), spheres in pairs.items():
    with h5py.File(os.path.join(work, f'a{n}_g{g}', 'series.h5'), 'r') as f:
        V = C.aitken(f['particles/velocity'][:])
    ex = pair_scalars(g)
    exact = (2 / 3) * (ex[I['XG11']] - ex[I['XG12']]) / (ex[I['XA11']] - ex[I['XA12']]) * ded
    u1, u2 = ((V[k] - spheres[k][1]) @ d for k in (0, 1))
    print(f'a/D {n} gap {g}: (U1-Uinf).d {u1:+.5f} (U2-Uinf).d {u2:+.5f} exact {exact:+.5f} '
          f'({100 * (u1 / exact - 1):+.2f} %)')
