#!/usr/bin/env python3
"""Period-two chatter in the core stresses of runs with &rheology (doc/CONTACT.md "Implicit
contacts"): for each output directory, from its series.h5,

  jump      the largest |s_{k+1} - 2 s_k + s_{k-1}| / 2 over the records from strain --from on and
            the components xx, yy, zz, xy of the hydrodynamic, contact and total core stress, in %
            of tau (the run's mean of gamma_dot_core + Sigma^p_xy over its second half): for an
            alternation s = m +- a it is 2a, the jump between consecutive records;
  period 2  the largest amplitude a of s = linear trend +- a over --window records (least squares,
            detrended), same components, in % of tau: a contact that closes in one step makes a
            jump but no alternation;
  means     over the second half: eta_r, eta_c, -Sigma^c_yy/tau, N1/tau, N2/tau, open pair
            contacts, sliding contacts, mean and largest overlap over h_r.

    scripts/chatter.py OUTDIR [OUTDIR ...] [--from 0.025] [--window 8]
"""
import argparse

import numpy as np

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp import series


def analyse(outdir, start, window):
    f, attrs = series.read(outdir)       # series.h5 and the records still in series.parts/
    t = f['time']
    h = f['core/stress_hydro'][:, :4]
    c = f['core/stress_contact'][:, :4]
    g = f['core/shear_rate']
    pairs, sliding = f['contacts_pair'], f['contacts_sliding']
    overlap = f['contact_max_overlap'] / attrs['roughness'] if 'roughness' in attrs else None
    if overlap is None:
        overlap = f['contact_overlap_over_roughness']
    late = t > t[-1] / 2 + 1e-12
    tau = np.mean(g[late] + h[late, 3] + c[late, 3])
    inner = t[1:-1] >= start - 1e-12
    jump, period2 = [], []
    sign = (-1.0) ** np.arange(window)
    basis = np.vstack([np.ones(window), np.arange(window)]).T
    project = np.eye(window) - basis @ np.linalg.pinv(basis)
    for s in (h, c, h + c):
        jump.append(100 * (np.abs(s[2:] - 2 * s[1:-1] + s[:-2])[inner] / 2).max() / tau)
        best = 0.0
        for k in range(len(t) - window + 1):
            if t[k] < start - 1e-12:
                continue
            best = max(best, np.abs(sign @ (project @ s[k:k + window])).max() / window)
        period2.append(100 * best / tau)
    gm = g[late].mean()
    sp = h + c
    eta = 1 + sp[late, 3].mean() / gm
    tau_mean = eta * gm
    means = dict(eta_r=eta, eta_c=c[late, 3].mean() / gm, Pc=-c[late, 1].mean() / tau_mean,
                 N1=(sp[late, 0].mean() - sp[late, 1].mean()) / tau_mean,
                 N2=(sp[late, 1].mean() - sp[late, 2].mean()) / tau_mean,
                 pairs=pairs[late].mean(), sliding=sliding[late].mean(),
                 overlap=overlap[late].mean(), overlap_max=overlap[late].max())
    return jump, period2, means


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('outdirs', nargs='+')
    ap.add_argument('--from', dest='start', type=float, default=0.025, help='first strain looked at')
    ap.add_argument('--window', type=int, default=8)
    args = ap.parse_args()
    print('%-32s %-22s %-22s %s' % ('run', 'jump % h/c/t', 'period 2 % h/c/t', 'second half'))
    for d in args.outdirs:
        jump, period2, m = analyse(d, args.start, args.window)
        print('%-32s %6.2f %6.2f %6.2f  %6.3f %6.3f %6.3f  ' % (d[-32:], *jump, *period2)
              + ' '.join('%s %.4g' % kv for kv in m.items()))


if __name__ == '__main__':
    main()
