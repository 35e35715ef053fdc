"""Order in shear at phi 0.55 in the DNS (walls): Q6 of the core's bonds against strain for equal
spheres and the 1:1.4 mixture, their g(r) in the core, and the wall layering.

    PYTHONPATH=python python3 doc/data/polydisperse/summarise_dns_order.py OUT_EQUAL OUT_MIXTURE JSON PNG

(the runs: bin/fdsusp doc/data/polydisperse/dns_order/equal.nml, mixture.nml; README.md "Order in the
DNS"). Between walls the program's structure/q6 counts the spheres layered at the walls too; the core
(y in [Ly/4, 3Ly/4], the summary's core) is where bulk order shows, so Q6 is recomputed here from the
recorded positions for the bonds with both ends in the core. Bonds as the program's (doc/RHEOLOGY.md
"Order"): centres closer than 1.4 (a_i + a_j), periodic in x and z. Q6 as Steinhardt, Nelson &
Ronchetti 1983; checked on an fcc lattice (0.5745) before use.
"""
import json
import math
import os
import sys

import h5py
import numpy as np
from numpy.polynomial import legendre

from fdsusp import series

L = 6
BOND_FACTOR = 1.4
# P_6^m as polynomials in cos(theta), and the normalisation of Y_6m
LEGENDRE_6M = [legendre.Legendre.basis(L).deriv(m) for m in range(L + 1)]
NORM = [math.sqrt((2 * L + 1) / (4 * math.pi) * math.factorial(L - m) / math.factorial(L + m))
        for m in range(L + 1)]


def y6(d):
    """Y_6m(d_hat) for m = 0..6 of bond vectors d (n, 3): (n, 7) complex (|Y_6,-m| = |Y_6m|)."""
    r = np.linalg.norm(d, axis=1)
    c = d[:, 2] / r
    s = np.sqrt(np.clip(1 - c * c, 0, None))
    phi = np.arctan2(d[:, 1], d[:, 0])
    return np.stack([NORM[m] * s ** m * LEGENDRE_6M[m](c) * np.exp(1j * m * phi) for m in range(L + 1)], axis=1)


def q6_of_bonds(d):
    """Global Q6 of bond vectors d (n, 3): each bond counted at both ends, which leaves the mean."""
    if len(d) == 0:
        return float('nan')
    q = y6(d).mean(axis=0)
    # m = 0 once, m = 1..6 twice (the -m terms)
    return math.sqrt(4 * math.pi / 13 * (abs(q[0]) ** 2 + 2 * np.sum(np.abs(q[1:]) ** 2)))


def bonds(x, radius, box, keep):
    """Bond vectors between spheres both in keep, periodic in x and z (walls in y)."""
    idx = np.flatnonzero(keep)
    p, a = x[idx], radius[idx]
    d = p[None, :, :] - p[:, None, :]
    for k in (0, 2):
        d[..., k] -= box[k] * np.round(d[..., k] / box[k])
    r = np.linalg.norm(d, axis=2)
    i, j = np.triu_indices(len(idx), 1)
    near = r[i, j] < BOND_FACTOR * (a[i] + a[j])
    return d[i[near], j[near]]


def radial_g(positions, box, lo, hi, rmax=4.0, width=0.05):
    """g(r) of sphere centres (all species together) around the spheres of the core [lo, hi],
    normalised by the core's number density; the records averaged. With the core 5a from each wall,
    shells up to rmax = 4 lie inside the cell (centres stay 1a from a wall), so none is cut."""
    edges = np.arange(0, rmax + width / 2, width)
    counts = np.zeros(len(edges) - 1)
    refs = 0
    density = 0.0
    for x in positions:
        inner = np.flatnonzero((x[:, 1] >= lo) & (x[:, 1] <= hi))
        d = x[None, :, :] - x[inner, None, :]
        for k in (0, 2):
            d[..., k] -= box[k] * np.round(d[..., k] / box[k])
        r = np.linalg.norm(d, axis=2)
        counts += np.histogram(r[r > 0], bins=edges)[0]
        refs += len(inner)
        density += np.count_nonzero((x[:, 1] >= lo) & (x[:, 1] <= hi)) / (box[0] * box[2] * (hi - lo))
    density /= len(positions)
    shell = 4 * math.pi / 3 * (edges[1:] ** 3 - edges[:-1] ** 3)
    return 0.5 * (edges[1:] + edges[:-1]), counts / max(refs, 1) / (density * shell)


def check_fcc():
    """Q6 of the 12 nearest-neighbour bonds of fcc: 0.5745 (Steinhardt et al. 1983, table I)."""
    v = np.array([(a, b, 0) for a in (1, -1) for b in (1, -1)] + [(a, 0, b) for a in (1, -1) for b in (1, -1)]
                 + [(0, a, b) for a in (1, -1) for b in (1, -1)], dtype=float)
    q = q6_of_bonds(v)
    assert abs(q - 0.5745) < 1e-3, q
    return q


def main(out_equal, out_mixture, json_path, png_path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    out = {'fcc_check_q6': check_fcc()}
    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for name, d in (('equal', out_equal), ('mixture', out_mixture)):
        s, a = series.read(d, ['time', 'shear/strain', 'structure/q6', 'particles/position',
                               'profiles/solid_fraction'])
        n = s['particles/position'].shape[1]
        with h5py.File(os.path.join(d, 'checkpoint.h5'), 'r') as f:
            # equal spheres' checkpoints hold no radii: the unit radius
            radius = f['particles/radius'][()].ravel() if 'particles/radius' in f else np.ones(n)
        box = np.array([a['box_x'], a['box_y'], a['box_z']]).ravel()
        lo, hi = float(a['core_lo'][0]), float(a['core_hi'][0])
        strain = s['shear/strain']
        q6_core = np.array([q6_of_bonds(bonds(x, radius, box, (x[:, 1] >= lo) & (x[:, 1] <= hi)))
                            for x in s['particles/position']])
        rows = {}
        for w0, w1 in [(0, 1)] + [(k, k + 2) for k in range(1, 20, 2)]:
            m = (strain >= w0) & (strain < w1)
            if m.any():
                rows['%d-%d' % (w0, w1)] = {'q6_core': float(q6_core[m].mean()),
                                            'q6_box': float(s['structure/q6'][m].mean())}
        out[name] = {'spheres': int(len(radius)), 'strain_last': float(strain[-1]),
                     'order_by_strain_window': rows}
        summary = os.path.join(d, 'summary.json')
        if os.path.exists(summary):   # written at the end of the run
            summ = json.load(open(summary))
            out[name].update({k: summ['quantities'][k] for k in ('eta_r', 'phi_core', 'N1/tau', 'N2/tau')},
                             blocks_complete=summ['blocks_complete'])
        label = '%s (%d spheres)' % (name, len(radius))
        ax[0].plot(strain, q6_core, label=label + ', core')
        ax[0].plot(strain, s['structure/q6'], lw=0.7, ls='--', label=label + ', whole cell')
        # g(r) of the core after strain 5, and over the last 2 strains
        for w0, w1, ls in ((5, 1e9, '-'), (strain[-1] - 2, 1e9, ':')):
            m = (strain >= w0) & (strain < w1)
            if not m.any():
                continue
            r, g = radial_g(s['particles/position'][m], box, lo, hi)
            ax[1].plot(r, g, lw=0.9, ls=ls, label='%s, strain >= %.0f' % (name, w0))
            out[name]['g_peak_strain_from_%.0f' % w0] = {'r': float(r[np.argmax(g)]), 'g': float(g.max())}
        # solid fraction across the gap, averaged after strain 5
        m = strain >= min(5, strain[-1] / 2)
        prof = s['profiles/solid_fraction'][m].mean(axis=0)
        y = (np.arange(len(prof)) + 0.5) * box[1] / len(prof)
        ax[2].plot(y, prof, lw=0.9, label=name)
        out[name]['wall_layer_peak_phi'] = float(prof[: len(prof) // 4].max())
    ax[0].axhline(0.5745, color='k', ls=':', lw=0.8, label='fcc crystal')
    ax[0].set_xlabel(r'strain $\dot\gamma t$')
    ax[0].set_ylabel(r'$Q_6$')
    ax[1].set_xlabel('r / a')
    ax[1].set_ylabel('g(r), core')
    ax[2].set_xlabel('y / a')
    ax[2].set_ylabel(r'solid fraction (strain $\geq$ 5)')
    for a_ in ax:
        a_.legend(fontsize=7)
    fig.suptitle('phi = 0.55, frictionless rough spheres, DNS between walls 20a apart (9a x 20a x 9a)')
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    json.dump(out, open(json_path, 'w'), indent=1)
    print(json.dumps(out, indent=1))


if __name__ == '__main__':
    main(*sys.argv[1:5])
