#!/usr/bin/env python3
"""Print a lubrication table (input/lubrication/resolved_a<N>.h5) beside the exact functions: per
gap, the pair part the grid resolves, its scatter over the calibration samples, and the exact
value, for the combinations that carry the lubrication singularities (doc/LUBRICATION.md). A
table of an unequal pair (resolved_a<N>_ratio<R>.h5) is printed scalar by scalar for each sphere,
beside the exact pair part folded as the table holds it (fdsusp.pair_blocks.exact_pair_part).
    scripts/lubrication_table.py [TABLE ...]"""
import argparse
import glob
import os

import h5py
import numpy as np

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.resistance import pair_scalars, wall_excess, NAMES
from fdsusp import pair_blocks as pb

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
UNEQUAL = ['XA', 'YA', 'YB', 'XC', 'YC', 'XG', 'XM']


def print_unequal(path, h):
    """Each sphere's self and cross scalars of the listed functions: resolved +- scatter, exact."""
    lam = float(h.attrs['size_ratio'])
    pair, scat = h['pair/resolved'][:], h['pair/scatter'][:]
    print(f"## {os.path.basename(path)}: a/Delta = {h.attrs['cells_per_radius']} (sphere 1), size ratio {lam:g}  "
          "(pair part; resolved +- scatter; exact)")
    names = [(n, sl) for n in UNEQUAL for sl in ('11', '12', '22', '21') if not (n == 'XM' and sl in ('12', '21'))]
    column = {'11': 0, '12': 11, '22': 22, '21': 33}
    print('%-8s' % 'gap' + ''.join('%25s' % (n + sl) for n, sl in names))
    for row, srow in zip(pair, scat):
        g = row[0]
        exact = np.concatenate(pb.to_arrays(pb.exact_pair_part(g, lam)))
        cells = []
        for n, sl in names:
            k = 1 + column[sl] + pb.K[n]
            cells.append('%8.3f +-%5.3f %8.3f' % (row[k], srow[k], exact[k - 1]))
        print('%-8g' % g + ''.join('%25s' % c for c in cells))


for path in args.tables or sorted(glob.glob(os.path.join(ROOT, 'input', 'lubrication', 'resolved_a*.h5'))):
    with h5py.File(path, 'r') as h:
        if float(h.attrs.get('size_ratio', 1.0)) != 1.0:
            print_unequal(path, h)
            continue
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
