#!/usr/bin/env python3
"""Print a lubrication table (input/lubrication/resolved_a<N>.h5) beside the exact functions: per
gap, the pair part the grid resolves, its scatter over the calibration samples, and the exact
value, for the combinations that carry the lubrication singularities (doc/LUBRICATION.md).
    scripts/lubrication_table.py [TABLE ...]"""
import argparse
import glob
import os

import h5py
import numpy as np

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.resistance import pair_scalars, wall_excess, NAMES

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

I = {n: k for k, n in enumerate(NAMES)}
COMBOS = [('XA11-XA12', lambda f: f[I['XA11']] - f[I['XA12']]),
          ('YA11-YA12', lambda f: f[I['YA11']] - f[I['YA12']]),
          ('YB11-YB12', lambda f: f[I['YB11']] - f[I['YB12']]),
          ('XC11', lambda f: f[I['XC11']]), ('YC11', lambda f: f[I['YC11']]),
          ('XM', lambda f: f[I['XM11']] + f[I['XM12']]), ('YM', lambda f: f[I['YM11']] + f[I['YM12']]),
          ('ZM', lambda f: f[I['ZM11']] + f[I['ZM12']])]
ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument('tables', nargs='*', metavar='TABLE', help='default: the shipped input/lubrication/resolved_a*.h5')
args = ap.parse_args()
for path in args.tables or sorted(glob.glob(os.path.join(ROOT, 'input', 'lubrication', 'resolved_a*.h5'))):
    with h5py.File(path, 'r') as h:
        n = h.attrs['cells_per_radius']
        pair, scat = h['pair/resolved'][:], h['pair/scatter'][:]
        wall, wscat = h['wall/resolved'][:], h['wall/scatter'][:]
    print(f'## {os.path.basename(path)}: a/Delta = {n}  (pair part = f - one-body value; resolved +- scatter; exact)')
    print('%-10s' % 'gap' + ''.join('%26s' % c[0] for c in COMBOS))
    # M: the table holds M11 + M12 in the 11 column and 0 in the 12 column
    for row, srow in zip(pair, scat):
        g, f, sf = row[0], row[1:], srow[1:]
        # the table stores M sums in the 11 slots
        f = f.copy(); sf = sf.copy()
        ex = pair_scalars(g)
        ex_pair = ex.copy()
        for k in ('XA11', 'YA11', 'XC11', 'YC11'):
            ex_pair[I[k]] -= 1.0
        for m in ('XM', 'YM', 'ZM'):
            ex_pair[I[m + '11']] = ex[I[m + '11']] + ex[I[m + '12']] - 1.0
            ex_pair[I[m + '12']] = 0.0
        cells = []
        for name, fn in COMBOS:
            # relative combinations were measured as D and stored as (S +- D)/2: std(D) = 2 std(f11)
            spread = 2 * sf[I[name[:4]]] if '-' in name else abs(fn(sf))
            cells.append('%9.4f +-%6.4f %8.4f' % (fn(f), spread, fn(ex_pair)))
        print('%-10g' % g + ''.join('%26s' % c for c in cells))
    print('%-10s' % 'wall gap' + ''.join('%26s' % c for c in ('lambda_perp', 'f_tt', 'f_tr', 'f_rr')))
    for row, srow in zip(wall, wscat):
        g = row[0]
        ex = wall_excess(g)
        print('%-10g' % g + ''.join('%9.4f +-%6.4f %8.4f' % (row[1 + k], srow[1 + k], ex[k]) for k in range(4)))
