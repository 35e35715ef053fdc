"""Summarise the shear-reversal runs (README.md): per run a NAME.summary.json here and the table
summary.json + table (markdown, printed), and the figure doc/figures/reversal_ld.png.

    PYTHONPATH=python /usr/bin/python3 doc/data/protocols/reversal/summarise_reversal.py [--out out/protocols/reversal]

Definitions (stresses in eta*|rate|, the solvent included in eta and eta_h; fdsusp.protocols):
- steady: the mean over the last strain before each reversal (strain since the previous reversal,
  or since the start, in [G - 1, G]) of eta = signed shear stress, eta_h (hydrodynamic + solvent),
  eta_c (contact), N1, N2; value +- standard error over the segments (one value per segment).
- transient: fdsusp.protocols.reversal_transient over every reversal: the mean at equal strain
  since reversal, +- standard error over the reversals.
- eta_min: the smallest mean eta over strain since reversal <= 2, with its strain, and eta_h,
  eta_c there; eta(0.02): the record nearest strain 0.02 after reversal.
- gamma_90: the strain since reversal at which the mean eta, smoothed over 0.1 strain, first
  regains 90 % of the drop, eta_min + 0.9 (eta_ss - eta_min); gamma_90c the same for eta_c (from
  its value at 0.02 to its steady value).
- eta_23, eta_c_23: the mean transient over strain 2-3 after reversal (the G = 3 runs' steady
  window), to set against the steady values of the G = 6 runs.
- gamma_50: the same for half the drop (the recovery is sigmoidal in strain, not exponential: an
  exponential fit from the minimum runs to its bound).
- steady shear: eta_r, eta_h, eta_c of the steady runs of doc/data/polydisperse/curves (equal
  spheres, 12a cube, eps_bar 0.015) at the same phi and mu_d, where they exist.
- errors of gamma_90, gamma_r, ratios: jackknife over the reversals (leave one out).
"""
import argparse
import glob
import json
import math
import os
import sys

import numpy as np

from fdsusp import protocols, series

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..', '..'))
NAMES = ['rev_mu0_p30', 'rev_mu0_p40', 'rev_mu0_p45', 'rev_mu05_p30', 'rev_mu05_p40', 'rev_mu05_p45',
         'rev_mu0_p30_g6', 'rev_mu05_p30_g6', 'rev_mu0_p40_g6', 'rev_mu05_p40_g6']
QUANTITIES = ('shear', 'shear_h', 'shear_c', 'N1', 'N2', 'N1_c', 'N2_c')


def segments(columns, dt):
    """Per record: the segment index (0 from the start, k after the k-th reversal) and the strain
    since its start (since the turning point as fdsusp.protocols finds it, or since t = 0)."""
    rate, strain, step = columns['shear/rate'], columns['shear/strain'], columns['step']
    sign = np.sign(rate)
    starts = np.flatnonzero(sign[1:] != sign[:-1]) + 1
    seg = np.zeros(len(rate), int)
    for a in starts:
        seg[a:] += 1
    since = np.abs(strain).copy()                  # segment 0: from strain 0
    for k, a in enumerate(starts):
        b = starts[k + 1] if k + 1 < len(starts) else len(rate)
        gr = (strain[a - 1] + strain[a] - rate[a] * dt * (step[a] - step[a - 1])) / 2
        since[a:b] = np.abs(strain[a:b] - gr)
    return seg, since, starts


def smooth(y, n):
    """Running mean over n records (centred; shorter at the ends), ignoring NaN."""
    out = np.full(len(y), np.nan)
    h = n // 2
    for i in range(len(y)):
        w = y[max(0, i - h):i + h + 1]
        w = w[np.isfinite(w)]
        if len(w):
            out[i] = w.mean()
    return out


def recovery(x, eta, eta_ss, start_value, start_index, per_01, fraction=0.9):
    """First strain at which the smoothed curve regains the fraction from start_value to eta_ss."""
    target = start_value + fraction * (eta_ss - start_value)
    s = smooth(eta, per_01)
    up = eta_ss > start_value
    for i in range(start_index, len(x)):
        if np.isfinite(s[i]) and ((s[i] >= target) if up else (s[i] <= target)):
            return float(x[i])
    return float('nan')


def measures(x, tables, eta_ss, G, per_01):
    """The transient's numbers from per-reversal tables (reversals x strain bins)."""
    mean = {q: np.nanmean(tables[q], axis=0) for q in tables}
    early = x <= 2.0 + 1e-9
    imin = int(np.nanargmin(np.where(early, mean['shear'], np.inf)))
    i02 = int(np.argmin(np.abs(x - 0.02)))
    out = {'strain_min': float(x[imin]), 'eta_min': float(mean['shear'][imin]),
           'eta_h_at_min': float(mean['shear_h'][imin]), 'eta_c_at_min': float(mean['shear_c'][imin]),
           'strain_002': float(x[i02])}
    for q in QUANTITIES:
        out[q + '_002'] = float(mean[q][i02])
    out['gamma_90'] = recovery(x, mean['shear'], eta_ss['shear'], out['eta_min'], imin, per_01)
    out['gamma_90c'] = recovery(x, mean['shear_c'], eta_ss['shear_c'], out['shear_c_002'], i02, per_01)
    out['gamma_50'] = recovery(x, mean['shear'], eta_ss['shear'], out['eta_min'], imin, per_01, 0.5)
    out['eta_h_max_early'] = float(np.nanmax(np.where(x <= 0.1 + 1e-9, mean['shear_h'], -np.inf)))
    out['ratio_c_002'] = out['shear_c_002'] / eta_ss['shear_c']
    w = (x >= 2.0 - 1e-9) & (x <= 3.0 + 1e-9)         # where the G = 3 runs take their steady values
    out['eta_23'] = float(np.nanmean(mean['shear'][w]))
    out['eta_c_23'] = float(np.nanmean(mean['shear_c'][w]))
    out['ratio_min'] = out['eta_min'] / eta_ss['shear']
    out['ratio_002'] = out['shear_002'] / eta_ss['shear']
    out['ratio_min_to_h'] = out['eta_min'] / eta_ss['shear_h']
    return out


def analyse(outdir, name):
    p = protocols.settings(outdir)
    G = p['reversal_strain']
    columns, attributes = series.read(outdir, protocols.STRESS_COLUMNS + ['step'])
    s = protocols.stresses(columns)
    sign = np.sign(columns['shear/rate'])
    seg, since, starts = segments(columns, p['dt'])
    # steady: last strain of every complete segment (the next reversal happened, or the run ended at G)
    steady = {q: [] for q in QUANTITIES}
    nseg = seg.max() + 1
    for k in range(nseg):
        m = (seg == k) & (since >= G - 1.0 - 1e-9)
        if since[seg == k].max() < G - 0.05:
            continue                                  # incomplete last segment
        for q in QUANTITIES:
            v = s[q] * sign if q.startswith('shear') else s[q]
            steady[q].append(float(np.mean(v[m])))
    ss = {q: float(np.mean(v)) for q, v in steady.items()}
    ss_err = {q: float(np.std(v, ddof=1) / math.sqrt(len(v))) if len(v) > 1 else float('nan')
              for q, v in steady.items()}
    # the transient and per-reversal tables (complete reversals: reaching G - 0.05)
    r = protocols.reversal_transient(outdir)
    x = r['strain']
    step_strain = x[1] - x[0]
    per_01 = max(1, int(round(0.1 / step_strain)))
    tables = {q: [] for q in QUANTITIES}
    for k, a in enumerate(starts):
        b = starts[k + 1] if k + 1 < len(starts) else len(since)
        if since[b - 1] < G - 0.05:
            continue
        bins = np.rint((since[a:b] - x[0]) / step_strain).astype(int)
        for q in QUANTITIES:
            row = np.full(len(x), np.nan)
            v = s[q] * sign if q.startswith('shear') else s[q]
            keep = bins < len(x)
            row[bins[keep]] = v[a:b][keep]
            tables[q].append(row)
    tables = {q: np.array(v) for q, v in tables.items()}
    n = len(tables['shear'])
    if n == 0 or len(steady['shear']) == 0:
        print(f'{name}: no complete reversal yet', file=sys.stderr)
        return None
    result = measures(x, tables, ss, G, per_01)
    # jackknife over the reversals (and their preceding steady segment)
    if n > 2:
        jack = []
        for j in range(n):
            t = {q: np.delete(v, j, axis=0) for q, v in tables.items()}
            ssj = {q: float(np.mean(np.delete(np.array(steady[q]), min(j, len(steady[q]) - 1)))) for q in steady}
            jack.append(measures(x, t, ssj, G, per_01))
        errors = {}
        for key in result:
            vals = np.array([jk[key] for jk in jack], float)
            if np.all(np.isfinite(vals)):
                errors[key] = float(math.sqrt((n - 1) / n * np.sum((vals - vals.mean()) ** 2)))
            else:
                errors[key] = float('nan')
    else:
        errors = {key: float('nan') for key in result}
    log = os.path.join(os.path.dirname(outdir), name + '.log')
    cpu = 0.0
    if os.path.exists(log):
        for line in open(log):
            if line.startswith('== ') and ' cpu user ' in line:
                w = line.split()
                cpu += float(w[4]) + float(w[7])
    mean = {q: np.nanmean(tables[q], axis=0) for q in ('shear', 'shear_h', 'shear_c')}
    transient = {'strain': [round(float(v), 6) for v in x[::2]]}
    for q in ('shear', 'shear_h', 'shear_c'):
        transient[q] = [round(float(v), 5) for v in mean[q][::2]]
        if n > 1:
            err = np.nanstd(tables[q], axis=0, ddof=1) / math.sqrt(n)
            transient[q + '_error'] = [round(float(v), 5) for v in err[::2]]
    every = float(np.median(np.diff(columns['step'])))
    out = {'name': name, 'reversal_strain': G, 'dt': p['dt'], 'reversals_averaged': n,
           'segments_steady': len(steady['shear']), 'last_step': int(columns['step'][-1]),
           'strain_total': float(columns['step'][-1] * p['dt'] * abs(p['reference_rate'])),
           'steady': ss, 'steady_error': ss_err, 'after_reversal': result, 'after_reversal_error': errors,
           'cpu_seconds': cpu, 'series_every': int(every), 'steady_shear_curves': steady_shear(name),
           'transient': transient}
    return out


def steady_shear(name):
    """eta_r, eta_h, eta_c of the steady curve at the run's phi and mu_d (doc/data/polydisperse/curves)."""
    mu = 'mu05' if 'mu05' in name else 'mu0'
    phi = name.split('_p')[1][:2]
    path = os.path.join(ROOT, 'doc', 'data', 'polydisperse', 'curves', f'eq_{mu}_p{phi}.summary.json')
    if not os.path.exists(path):
        return None
    d = json.load(open(path))
    d = d['quantities']
    return {q: [d[q]['value'], d[q]['error']] for q in ('eta_r', 'eta_h', 'eta_c')}


def fmt(v, e=None, d=2):
    if v is None or not np.isfinite(v):
        return '-'
    if e is None or not np.isfinite(e):
        return f'{v:.{d}f}'
    return f'{v:.{d}f} +- {e:.{d}f}'


def table(runs):
    head = ('| run | phi | mu_d | G | reversals | eta_r (steady shear) | eta_r | eta_h | eta_c | eta_min (strain) | eta_h, eta_c at min | '
            'eta(0.02): eta_h, eta_c | eta_min/eta_r | eta_min/eta_h | gamma_90 | gamma_90c | gamma_50 | N1, N2 steady | N1, N2 at 0.02 |')
    lines = [head, '|' + '---|' * (head.count('|') - 1)]
    for r in runs:
        ss, se, a, ae = r['steady'], r['steady_error'], r['after_reversal'], r['after_reversal_error']
        phi = int(r['name'].split('_p')[1][:2]) / 100
        c = r.get('steady_shear_curves')
        curve = fmt(c['eta_r'][0], c['eta_r'][1], 1) if c else '-'
        mu = 0.5 if 'mu05' in r['name'] else 0.0
        lines.append(
            f"| {r['name']} | {phi:.2f} | {mu} | {r['reversal_strain']:g} | {r['reversals_averaged']} | {curve} | {fmt(ss['shear'], se['shear'])} | "
            f"{fmt(ss['shear_h'], se['shear_h'])} | {fmt(ss['shear_c'], se['shear_c'])} | "
            f"{fmt(a['eta_min'], ae['eta_min'])} ({a['strain_min']:.3f}) | {fmt(a['eta_h_at_min'])}, {fmt(a['eta_c_at_min'])} | "
            f"{fmt(a['shear_002'], ae['shear_002'])}: {fmt(a['shear_h_002'])}, {fmt(a['shear_c_002'], ae['shear_c_002'])} | "
            f"{fmt(a['ratio_min'], ae['ratio_min'])} | {fmt(a['ratio_min_to_h'], ae['ratio_min_to_h'])} | "
            f"{fmt(a['gamma_90'], ae['gamma_90'])} | {fmt(a['gamma_90c'], ae['gamma_90c'])} | {fmt(a['gamma_50'], ae['gamma_50'])} | "
            f"{fmt(ss['N1'], se['N1'])}, {fmt(ss['N2'], se['N2'])} | {fmt(a['N1_002'], ae['N1_002'])}, {fmt(a['N2_002'], ae['N2_002'])} |")
    return '\n'.join(lines)


def figure(runs, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    byname = {r['name']: r for r in runs}
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5))
    for i, mu in enumerate(('0', '05')):
        for j, p in enumerate(('30', '40', '45')):
            ax = axes[i, j]
            r = byname.get(f'rev_mu{mu}_p{p}')
            r6 = byname.get(f'rev_mu{mu}_p{p}_g6')
            if r6:
                t6 = r6['transient']
                ax.plot(t6['strain'], t6['shear'], color='0.45', lw=0.9, ls='--', label='eta, G = 6')
                ax.plot(t6['strain'], t6['shear_c'], color='salmon', lw=0.9, ls='--', label='eta_c, G = 6')
            ax.set_title(f'phi 0.{p}, mu_d {"0" if mu == "0" else "0.5"}' + ('' if r else ' (not run)'), fontsize=10)
            if not r:
                continue
            t = r['transient']
            x = np.array(t['strain'])
            for q, col, lab in (('shear', 'k', 'eta'), ('shear_h', 'tab:blue', 'eta_h'), ('shear_c', 'tab:red', 'eta_c')):
                y = np.array(t[q], float)
                e = np.array(t.get(q + '_error', [np.nan] * len(y)), float)
                ax.plot(x, y, color=col, lw=1, label=lab)
                ax.fill_between(x, y - e, y + e, color=col, alpha=0.2, lw=0)
                ax.axhline(r['steady'][q], color=col, ls=':', lw=0.8)
            ax.set_xscale('log')
            ax.set_xlim(5e-3, r6['reversal_strain'] if r6 else r['reversal_strain'])
            ax.set_ylim(bottom=min(0, np.nanmin(t['shear_c'])))
            a = r['after_reversal']
            if np.isfinite(a['gamma_90']):
                ax.axvline(a['gamma_90'], color='gray', ls='--', lw=0.8)
            ax.text(0.03, 0.95, f"{r['reversals_averaged']} reversals\neta_min/eta_r {a['ratio_min']:.2f}\ngamma_90 {a['gamma_90']:.2f}",
                    transform=ax.transAxes, va='top', fontsize=8)
            if i == 1:
                ax.set_xlabel('strain since reversal')
            if j == 0:
                ax.set_ylabel('stress / (eta |gamma_dot|)')
            if (i == 0 and j == 0) or r6:
                ax.legend(fontsize=7, loc='center left')
    fig.suptitle('Shear reversal, lubrication dynamics (10a Lees-Edwards cube, eps_r 5e-3): mean over reversals +- s.e.; '
                 'dotted: steady values (G = 3); dashed: G = 6 runs', fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', default=os.path.join(ROOT, 'out', 'protocols', 'reversal'))
    ap.add_argument('--figure', default=os.path.join(ROOT, 'doc', 'figures', 'reversal_ld.png'))
    args = ap.parse_args()
    runs = []
    for name in NAMES:
        d = os.path.join(args.out, name)
        if os.path.exists(os.path.join(d, 'series.h5')):
            try:
                r = analyse(d, name)
            except protocols.NoProtocol:
                r = None
            if r is None:
                continue
            with open(os.path.join(HERE, name + '.summary.json'), 'w') as f:
                json.dump(r, f, indent=1)
            runs.append(r)
        elif os.path.exists(os.path.join(HERE, name + '.summary.json')):
            runs.append(json.load(open(os.path.join(HERE, name + '.summary.json'))))
    compact = [{k: v for k, v in r.items() if k != 'transient'} for r in runs]
    with open(os.path.join(HERE, 'summary.json'), 'w') as f:
        json.dump(compact, f, indent=1)
    t = table(runs)
    with open(os.path.join(HERE, 'table.md'), 'w') as f:
        f.write(t + '\n')
    print(t)
    print('cpu seconds: %.0f (%s)' % (sum(r['cpu_seconds'] for r in runs),
                                       ', '.join('%s %.0f' % (r['name'], r['cpu_seconds']) for r in runs)))
    figure(runs, args.figure)


if __name__ == '__main__':
    sys.exit(main())
