#!/usr/bin/env python3
"""Issue 44: the jamming runs at phi 0.55, mu_d 0.5, strain by strain (doc/VALIDATION.md §6
"Shear jamming, revisited"). For each run directory (out/shear_jamming/NAME, its series.h5), over
successive windows of 0.25 strain: eta_r, eta_h, eta_c, phi_core and the core's measured shear
rate as fdsusp's summary defines them (fdsusp.rheology.strain_windows: the whole box with
Lees-Edwards boundaries, the core between walls, stresses over the spheres' measured rate there),
and the largest contact overlap (in a: compare h_r = 5e-3 a for rough spheres, the guard), the
contacts and the sliding ones; then the mean eta_r over the whole windows from strain --from, with
the standard error of the windows. Writes NAME.summary.json beside the decks.

    PYTHONPATH=python doc/data/shear_jamming/summarise_jamming.py out/shear_jamming/NAME ... [--from 0.75]
"""
import argparse
import json
import os

import h5py
import numpy as np

from fdsusp import rheology

HERE = os.path.dirname(os.path.abspath(__file__))
WINDOW = 0.25
STRESSES = ['eta_r', 'eta_h', 'eta_c', 'phi_core', 'gamma_dot_core']


def windows(path):
    """The rows of 0.25-strain windows, and the strain the run reached."""
    a, s = rheology.load(path)
    stress = rheology.strain_windows(a, s, WINDOW, STRESSES)
    with h5py.File(os.path.join(path, 'series.h5'), 'r') as f:
        strain = f['time'][:] * abs(a['shear_rate'])
        overlap, pairs, sliding = f['contact_max_overlap'][:], f['contacts_pair'][:], f['contacts_sliding'][:]
    rows = []
    for k, lo in enumerate(stress['strain_start']):
        m = (strain > lo + 1e-9) & (strain <= lo + WINDOW + 1e-9)
        row = {'strain': [round(lo, 4), round(lo + WINDOW, 4)]}
        row.update({n: stress[n][k] for n in STRESSES})
        row.update({'max_overlap_a': float(overlap[m].max()), 'contacts': float(pairs[m].mean()),
                    'sliding': float(sliding[m].mean())})
        rows.append(row)
    return rows, float(strain[-1])


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
        eta = np.array([r['eta_r'] for r in late])
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
            print('  %.2f-%.2f  eta_r %7.1f  eta_h %5.1f  eta_c %7.1f  gamma_dot_core %.3f  phi_core %.4f  '
                  'max overlap %.4f a  contacts %4.0f  sliding %4.0f'
                  % (r['strain'][0], r['strain'][1], r['eta_r'], r['eta_h'], r['eta_c'], r['gamma_dot_core'],
                     r['phi_core'], r['max_overlap_a'], r['contacts'], r['sliding']))
        if 'eta_r' in out:
            print('  eta_r from strain %.2f: %.1f +- %.1f (%d windows), largest overlap %.4f a'
                  % (args.start, out['eta_r']['value'], out['eta_r']['error'], out['eta_r']['windows'],
                     out['max_overlap_a']))


if __name__ == '__main__':
    main()
