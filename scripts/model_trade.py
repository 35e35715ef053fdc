#!/usr/bin/env python3
"""Issue 30: what dropping the resolved fluid costs in accuracy and buys in speed. The same decks,
the same packings (the in-run packing of the same seed in the same box), run with the resolved fluid
(the DNS) and in lubrication dynamics (`&fluid model = 'none'`), at mu_d 0 and 0.5, side by side.

    scripts/model_trade.py [CASE ...] [--mu 0 0.5] [--jobs 2] [--ranks 1] [--hours 0]
                           [--work out/model_trade] [--record doc/data/model_trade]
                           [--table] [--list] [--rerecord]
    scripts/model_trade.py --figure doc/figures/model_trade.png

CASE names a row of ROWS (default: every row but the paper-scale ones), run at every --mu, or
ROW:MU for one run. Runs are made, resumed and recorded as by fdsusp.study
(doc/data/model_trade/<row>_mu<mu>/deck.nml and summary.json, with the CPU seconds per strain).
The DNS of the §5.4 set-up at phi 0.4 and of the paper's set-up are the friction study's records
(doc/data/friction_phi04, rows base and paperdt2): the same decks with the fluid resolved.
--table prints, per case and mu_d, both models' eta_r, eta_h, eta_c, N1/tau, N2/tau, Pi/tau and
phi_core with their block errors, the difference in eta_r in units of its combined error, and the
CPU seconds per strain; and Lees-Edwards against walls in lubrication dynamics.
"""
import math
import os
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.study import BASE, Study, load, run_name  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))

LD = dict(model='none')
ROWS = {
    'ld':          ('lubrication dynamics, the §5.4 set-up (its DNS: friction study row base)', dict(LD)),
    # stiffer contacts: ld at mu_d 0.5 stops on the overlap guard at strain 21.6 (largest overlap of
    # a record 0.47 h_r on average, 0.98 at the 99.9th percentile; the DNS: 0.37); eps_bar 0.02
    # with dt 8e-4 keeps the stick number at 4.6, where the DNS showed eps_bar not to matter
    'ld_eb002':    ('lubrication dynamics, eps_bar 0.02, dt 8e-4', dict(LD, eps_bar=0.02, dt=8e-4)),
    'ld_le':       ('lubrication dynamics, Lees-Edwards in y instead of walls, 8a x 20a x 8a',
                    dict(LD, boundary='lees-edwards')),
    'dns_phi0.3':  ('DNS, the §5.4 set-up at bulk phi 0.3', dict(phi=0.3)),
    'ld_phi0.3':   ('lubrication dynamics, the §5.4 set-up at bulk phi 0.3', dict(LD, phi=0.3)),
    'dns_phi0.45': ('DNS, the §5.4 set-up at bulk phi 0.45', dict(phi=0.45)),
    'ld_phi0.45':  ('lubrication dynamics, the §5.4 set-up at bulk phi 0.45', dict(LD, phi=0.45)),
    # the knobs of lubrication dynamics at phi 0.4 (the &lubrication outer_cutoff default is 1a)
    'ld_cut0.5':   ('lubrication dynamics, pair and wall resistance cut at a gap of 0.5a', dict(LD, cutoff=0.5)),
    # (a cut-off of 2a needs periods of at least 2 (2a + 2a + skin): the 8a box refuses it)
    'ld_cut1.5':   ('lubrication dynamics, pair and wall resistance cut at a gap of 1.5a', dict(LD, cutoff=1.5)),
    'ld_dt5e-3':   ('lubrication dynamics, dt 5e-3 (stick number 11.4 at mu_d 0.5)', dict(LD, dt=5e-3)),
    # at phi 0.45 and mu_d 0.5 eps_bar 0.05 reaches the overlap guard within a strain (step 409)
    'ld_phi0.45_eb002': ('lubrication dynamics at bulk phi 0.45, eps_bar 0.02, dt 8e-4',
                         dict(LD, phi=0.45, eps_bar=0.02, dt=8e-4)),
    # at phi 0.45 and mu_d 0.5 the DNS too reaches the overlap guard with eps_bar 0.05 (step 539)
    'dns_phi0.45_eb002': ('DNS at bulk phi 0.45, eps_bar 0.02, dt 8e-4 (run at mu_d 0.5 only: without friction eps_bar '
                          'does not matter, §5.4)', dict(phi=0.45, eps_bar=0.02, dt=8e-4)),
    # the cut-off 0.5a at the other fractions (is 0.5a's agreement with the DNS at phi 0.4 general?)
    'ld_phi0.3_cut0.5': ('lubrication dynamics at bulk phi 0.3, pair and wall resistance cut at 0.5a',
                         dict(LD, phi=0.3, cutoff=0.5)),
    'ld_phi0.45_cut0.5': ('lubrication dynamics at bulk phi 0.45, cut-off 0.5a, eps_bar 0.02, dt 8e-4',
                          dict(LD, phi=0.45, cutoff=0.5, eps_bar=0.02, dt=8e-4)),
    'ld_paper':    ('lubrication dynamics, the paper\'s set-up at dt 2e-3 (its DNS: friction study row paperdt2)',
                    dict(LD, box=(20, 20, 20), cells=5)),
}
DEFAULT = [r for r in ROWS if r != 'ld_paper']

FRICTION_RECORD = os.path.join(ROOT, 'doc', 'data', 'friction_phi04')
# (case, where the DNS record is: (record directory or None for this study's, row or {mu_d: row}),
# LD rows). At phi 0.45 with friction eps_bar 0.05 stops both models on the overlap guard: the DNS
# there is row dns_phi0.45_eb002 (without friction eps_bar does not matter, §5.4)
PAIRS = [
    ('phi 0.3, §5.4 set-up', (None, 'dns_phi0.3'), ['ld_phi0.3', 'ld_phi0.3_cut0.5']),
    ('phi 0.4, §5.4 set-up', (FRICTION_RECORD, 'base'), ['ld', 'ld_eb002', 'ld_cut0.5']),
    ('phi 0.45, §5.4 set-up', (None, {0.0: 'dns_phi0.45', 0.5: 'dns_phi0.45_eb002'}),
     ['ld_phi0.45', 'ld_phi0.45_eb002', 'ld_phi0.45_cut0.5']),
    ('phi 0.4, paper set-up', (FRICTION_RECORD, 'paperdt2'), ['ld_paper']),
]
QUANTITIES = ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'phi_core')


def cpu_per_strain(s):
    """CPU seconds per strain of a record: the runs' own count where recorded, else (the friction
    study's older records) the logged wall time per step times ranks and steps per strain (one rank
    per core, so wall and CPU agree)."""
    run = s['run']
    if run.get('cpu_seconds_per_strain'):
        return run['cpu_seconds_per_strain']
    if run.get('wall_time_per_step_s'):
        return run['wall_time_per_step_s'] * run.get('ranks', 1) / run['dt']
    return float('nan')


def dns_record(study, where, row, mu):
    """The DNS record of a case: in the friction study's records (where) or this study's (None);
    row may name one row per mu_d."""
    if isinstance(row, dict):
        row = row[mu]
    return load(os.path.join(where or study.record_dir, run_name(row, mu), 'summary.json'))


def pm(q):
    return '%.3g +- %.2g' % (q['value'], q['error'])


def table(study, rows):
    print('| case | mu_d | model | spheres | ' + ' | '.join(QUANTITIES) +
          ' | eta_r LD/DNS (sigmas) | CPU s per strain |')
    print('|---' * (len(QUANTITIES) + 6) + '|')
    for case, (where, dns_row), ld_rows in PAIRS:
        for mu in (0.0, 0.5):
            dns = dns_record(study, where, dns_row, mu)
            for model, s in [('DNS', dns)] + [('LD ' + r, study.load_record(r, mu)) for r in ld_rows]:
                if s is None:
                    print('| %s | %g | %s | (not run) |' % (case, mu, model))
                    continue
                q = s['quantities']
                extra = ''
                if model != 'DNS' and dns is not None:
                    a, b = dns['quantities']['eta_r'], q['eta_r']
                    extra = '%.3f (%+.1f)' % (b['value'] / a['value'],
                                              (b['value'] - a['value']) / math.hypot(a['error'], b['error']))
                print('| %s | %g | %s | %s | %s | %s | %.3g |' % (
                    case, mu, model, s['run']['spheres'], ' | '.join(pm(q[k]) for k in QUANTITIES), extra,
                    cpu_per_strain(s)))
    knobs = ('ld', 'ld_cut0.5', 'ld_cut1.5', 'ld_dt5e-3', 'ld_eb002')
    print_ld_rows(study, 'The knobs of lubrication dynamics at phi 0.4 (rows %s)' % ', '.join(knobs),
                  [(r, r) for r in knobs])
    print_ld_rows(study, 'Lees-Edwards against walls in lubrication dynamics (walls: the core; Lees-Edwards: '
                  'the whole box)', [('ld', 'walls'), ('ld_le', 'Lees-Edwards')])


def print_ld_rows(study, title, rows):
    """One table of recorded lubrication-dynamics rows, (row, label) each, at both mu_d."""
    print()
    print(title)
    print('| mu_d | row | ' + ' | '.join(QUANTITIES) + ' | CPU s per strain |')
    print('|---' * (len(QUANTITIES) + 3) + '|')
    for mu in (0.0, 0.5):
        for row, label in rows:
            s = study.load_record(row, mu)
            if s is not None:
                print('| %g | %s | %s | %.3g |' % (mu, label, ' | '.join(pm(s['quantities'][k]) for k in QUANTITIES),
                                                 cpu_per_strain(s)))


def figure(study, path):
    """eta_r, eta_h, eta_c, N1/tau, N2/tau and Pi/tau against phi_core, DNS (filled) and lubrication
    dynamics (open), mu_d 0 (blue) and 0.5 (red), with the Zarraga et al. (2000) viscosity and the
    Dai et al. (2013) normal-stress fits (fdsusp.references)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    import numpy as np
    from fdsusp.references import dai_normal, zarraga_eta
    names = ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau')
    fig, axes = plt.subplots(2, 3, figsize=(12, 7))
    phi = np.linspace(0.28, 0.47, 50)
    axes[0, 0].plot(phi, zarraga_eta(phi), 'k--', lw=1, label='Zarraga et al. 2000')
    axes[1, 0].plot(phi, dai_normal(phi)[0], 'k--', lw=1, label='Dai et al. 2013')
    axes[1, 1].plot(phi, dai_normal(phi)[1], 'k--', lw=1, label='Dai et al. 2013')
    seen = set()
    for case, (where, dns_row), ld_rows in PAIRS:
        for mu, colour in ((0.0, 'C0'), (0.5, 'C3')):
            dns = dns_record(study, where, dns_row, mu)
            runs = [('DNS', dns, 'o', colour)] + [('LD', study.load_record(r, mu), 's', 'none') for r in ld_rows]
            for model, s, marker, face in runs:
                if s is None:
                    continue
                label = '%s, mu_d %g' % (model, mu)
                for ax, name in zip(axes.flat, names):
                    q, x = s['quantities'][name], s['quantities']['phi_core']
                    ax.errorbar(x['value'], q['value'], xerr=x['error'], yerr=q['error'], fmt=marker,
                                mfc=face, mec=colour, ecolor=colour, ms=7 if 'paper' in case else 5,
                                label=None if label in seen else label)
                seen.add(label)
    for ax, name in zip(axes.flat, names):
        ax.set_xlabel('phi_core')
        ax.set_title(name)
    axes[0, 0].set_yscale('log')
    axes[0, 0].legend(fontsize=7)
    axes[1, 0].legend(fontsize=7)
    fig.suptitle('The DNS against lubrication dynamics (LD): the same decks and packings, '
                 'Couette walls, core values (large symbols: the paper\'s 20a cube)', fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print('wrote', path)


STUDY = Study('issue 30 model trade', ROWS, BASE, DEFAULT,
              work=os.path.join(ROOT, 'out', 'model_trade'),
              record=os.path.join(ROOT, 'doc', 'data', 'model_trade'), table=table, doc=__doc__)

if __name__ == '__main__':
    if '--figure' in sys.argv:      # --figure PATH: draw the records, run nothing
        figure(STUDY, sys.argv[sys.argv.index('--figure') + 1])
        sys.exit(0)
    sys.exit(STUDY.main())
