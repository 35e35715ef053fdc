#!/usr/bin/env python3
"""Issue 44: the jamming runs at phi 0.55, mu_d 0.5, strain by strain (doc/VALIDATION.md §6
"Shear jamming, revisited"). For each run directory (out/shear_jamming/NAME, its series.h5), the
whole-box (Lees-Edwards) or core (walls) stresses over successive windows of 0.25 strain: the
contact and hydrodynamic shear viscosities eta_c = Sigma^c_xy and eta_h = 1 + Sigma^h_xy (units
eta gamma_dot), the largest contact overlap (in a: compare h_r = 5e-3 a for rough spheres, the
guard), the contacts and the sliding ones, the solid fraction of the core (walls) or box; and the mean over strain >= --from with the standard
error of its whole windows. Writes NAME.summary.json beside the decks.

    doc/data/shear_jamming/summarise_jamming.py out/shear_jamming/sm055_k3.5e7 ... [--from 0.75]
"""
import argparse
import json
import os

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
WINDOW = 0.25


def windows(path):
    with h5py.File(os.path.join(path, 'series.h5'), 'r') as f:
        t = f['time'][:]
        contact, hydro = f['core/stress_contact'][:], f['core/stress_hydro'][:]
        overlap, pairs, sliding = f['contact_max_overlap'][:], f['contacts_pair'][:], f['contacts_sliding'][:]
        phi = f['core/solid_fraction'][:]
    rows = []
    for lo in np.arange(0.0, t[-1] + 1e-9, WINDOW):
        m = (t > lo) & (t <= lo + WINDOW + 1e-9)
        if m.sum() < 2:
            continue
        rows.append({'strain': [round(lo, 4), round(lo + WINDOW, 4)],
                     'eta_c': float(contact[m, 3].mean()), 'eta_h': float(1 + hydro[m, 3].mean()),
                     'max_overlap_a': float(overlap[m].max()), 'contacts': float(pairs[m].mean()),
                     'phi_core': float(phi[m].mean()),
                     'sliding': float(sliding[m].mean())})
    return rows, float(t[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--from', dest='start', type=float, default=0.75, help='strain from which to average')
    args = ap.parse_args()
    for run in args.runs:
        name = os.path.basename(os.path.normpath(run))
        rows, end = windows(run)
        # whole windows only: the last, partial one is printed but not averaged
        late = [r for r in rows if r['strain'][0] >= args.start - 1e-9 and r['strain'][1] <= end + 1e-6]
        eta = np.array([r['eta_c'] + r['eta_h'] for r in late])
        out = {'run': name, 'deck': name + '.nml', 'last_strain': end, 'windows': rows,
               'average_from_strain': args.start}
        if len(eta) >= 2:
            out['eta_r'] = {'value': float(eta.mean()), 'error': float(eta.std(ddof=1) / np.sqrt(len(eta))),
                            'windows': len(eta)}
            out['max_overlap_a'] = max(r['max_overlap_a'] for r in late)
        with open(os.path.join(HERE, name + '.summary.json'), 'w') as f:
            json.dump(out, f, indent=1)
        print('%s: to strain %.2f' % (name, end))
        for r in rows:
            print('  %.2f-%.2f  eta_c %7.1f  eta_h %5.1f  max overlap %.4f a  contacts %4.0f  sliding %4.0f  phi_core %.4f'
                  % (r['strain'][0], r['strain'][1], r['eta_c'], r['eta_h'], r['max_overlap_a'], r['contacts'],
                     r['sliding'], r['phi_core']))
        if 'eta_r' in out:
            print('  eta_r from strain %.2f: %.1f +- %.1f (%d windows), largest overlap %.4f a'
                  % (args.start, out['eta_r']['value'], out['eta_r']['error'], out['eta_r']['windows'],
                     out['max_overlap_a']))


if __name__ == '__main__':
    main()
