"""Stress control near shear jamming (README.md here): the flow curve at phi 0.50 and the creep at
phi 0.57 and 0.589, and the rate-controlled branch from the sheared state at 0.589, from the runs'
output, into summary.json and doc/figures/stress_near_jamming.png.
    PYTHONPATH=python python3 doc/data/protocols/stress_near_jamming/summarise.py [OUT]
OUT: out/protocols/stress_near_jamming (each run's output directory there, by deck name)."""
import json
import os
import sys

import numpy as np
from fdsusp import protocols, series

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..', '..'))
OUT = sys.argv[1] if len(sys.argv) > 1 else 'out/protocols/stress_near_jamming'
FLOW = ('flow_p50_S21', 'flow_p50_S42', 'flow_p50_S84')
CREEP = ('creep_p57_S130', 'creep_p59_S130')
SUB_BLOCKS = 8
# rate control, the same packings (doc/data/polydisperse/curves: eq_mu05_p50, eq_mu05_p57s)
RATE_CONTROL = {'p50': {'eta_r': 41.8, 'error': 1.1}, 'p57': {'eta_r': 132.0, 'error': 11.0}}


def load(name):
    cols, attrs = series.read(os.path.join(OUT, name), ['step', 'time', 'shear/rate', 'shear/strain', 'shear/stress',
                                                         'core/stress_contact'])
    return cols, series.settings(attrs)


def flow(name):
    """The mean rate over the &rheology window (fdsusp.protocols.stress_control_rate: the summary's
    blocks) and, for an error that sees the fluctuations, over SUB_BLOCKS equal sub-blocks."""
    cols, a = load(name)
    v = protocols.stress_control_rate(os.path.join(OUT, name))
    window = cols['step'] > int(a['discard_step'])
    means = np.array([b.mean() for b in np.array_split(cols['shear/rate'][window], SUB_BLOCKS)])
    rate, error = means.mean(), means.std(ddof=1) / np.sqrt(SUB_BLOCKS)
    contact = cols['core/stress_contact'][window, 3].mean()
    return {'stress': v['stress'], 'rate': rate, 'rate_error': error, 'eta_r': v['stress'] / rate,
            'eta_r_error': v['stress'] * error / rate ** 2, 'eta_c_share': contact / v['stress'],
            'rate_summary_blocks': v['rate'], 'time': float(cols['time'][-1]),
            'strain': float(cols['shear/strain'][-1])}


def creep(name):
    """The strain against time, and the rate at the end (mean over the last 20 % of the records)."""
    cols, a = load(name)
    t, g, r = cols['time'], cols['shear/strain'], cols['shear/rate']
    late = t >= 0.8 * t[-1]
    marks = [x for x in (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75) if x <= t[-1] + 1e-9]
    return {'stress': float(a['shear_stress']), 'time': float(t[-1]), 'strain': float(g[-1]),
            'rate_at_end': float(r[late].mean()), 'rate_first_record': float(r[0]),
            'strain_at': [[x, float(np.interp(x, t, g))] for x in marks],
            'contact_share_at_end': float(cols['core/stress_contact'][late, 3].mean() / a['shear_stress'])}


def figure(result):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    f = [result['flow'][n] for n in FLOW if n in result['flow']]
    left.errorbar([q['stress'] for q in f], [q['rate'] for q in f], yerr=[q['rate_error'] for q in f], fmt='s',
                  color='C1', capsize=3, label='stress control (LD, phi 0.50, mu_d 0.5)')
    s = np.linspace(0, 90, 10)
    left.plot(s, s / RATE_CONTROL['p50']['eta_r'], 'k--', lw=1, label='rate control at rate 1: eta_r 41.8')
    left.set_xlabel(r'imposed shear stress $S/(\eta\dot\gamma_{ref})$')
    left.set_ylabel(r'mean rate $\langle\dot\gamma\rangle/\dot\gamma_{ref}$')
    left.legend(fontsize=7)
    left.grid(alpha=0.3)
    for name, label, c in (('creep_p57_S130', 'phi 0.570 (flows under rate control)', 'C0'),
                           ('creep_p59_S130', 'phi 0.589 (its start-up jams under rate control)', 'C3')):
        if name not in result['creep']:
            continue
        cols, _ = load(name)
        right.plot(cols['time'], cols['shear/strain'], color=c, label=label)
    right.set_xlabel(r'time $\dot\gamma_{ref} t$')
    right.set_ylabel('strain')
    right.set_title('creep at S = 130 (mu_d 0.5)', fontsize=9)
    right.legend(fontsize=7)
    right.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, 'doc', 'figures', 'stress_near_jamming.png'), dpi=100)


if __name__ == '__main__':
    result = {'flow': {}, 'creep': {}, 'rate_control': RATE_CONTROL}
    for n in FLOW:
        if os.path.exists(os.path.join(OUT, n, 'series.h5')):
            result['flow'][n] = flow(n)
    for n in CREEP:
        if os.path.exists(os.path.join(OUT, n, 'series.h5')):
            result['creep'][n] = creep(n)
    # rate control branched from creep_p59_S130 at step 12500: its own summary (fdsusp's)
    branch = os.path.join(OUT, 'branch_p59_rate', 'summary.json')
    if os.path.exists(branch):
        q = json.load(open(branch))['quantities']
        result['branch_p59_rate'] = {k: q[k] for k in ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'mu')}
    json.dump(result, open(os.path.join(HERE, 'summary.json'), 'w'), indent=1)
    print(json.dumps(result, indent=1))
    figure(result)
