#!/usr/bin/env python3
"""Issue 30: what dropping the resolved fluid costs in accuracy and buys in speed. The same decks,
the same packings (the in-run packing of the same seed in the same box), run with the resolved fluid
(the DNS) and in lubrication dynamics (`&fluid model = 'none'`), at mu_d 0 and 0.5, side by side.

    scripts/model_trade.py [CASE ...] [--mu 0 0.5] [--jobs 2] [--ranks 1] [--hours 0]
                           [--work out/model_trade] [--record doc/data/model_trade]
                           [--table] [--list] [--rerecord]

CASE names a row of ROWS (default: every row but the paper-scale ones), run at every --mu, or
ROW:MU for one run. Runs are made, resumed and recorded as by scripts/study.py
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study import BASE, ROOT, Study, load, run_name  # noqa: E402

LD = dict(model='none')
ROWS = {
    'ld':          ('lubrication dynamics, the §5.4 set-up (its DNS: friction study row base)', dict(LD)),
    'ld_le':       ('lubrication dynamics, Lees-Edwards in y instead of walls, 8a x 20a x 8a',
                    dict(LD, boundary='lees-edwards')),
    'dns_phi0.3':  ('DNS, the §5.4 set-up at bulk phi 0.3', dict(phi=0.3)),
    'ld_phi0.3':   ('lubrication dynamics, the §5.4 set-up at bulk phi 0.3', dict(LD, phi=0.3)),
    'dns_phi0.45': ('DNS, the §5.4 set-up at bulk phi 0.45', dict(phi=0.45)),
    'ld_phi0.45':  ('lubrication dynamics, the §5.4 set-up at bulk phi 0.45', dict(LD, phi=0.45)),
    'ld_paper':    ('lubrication dynamics, the paper\'s set-up at dt 2e-3 (its DNS: friction study row paperdt2)',
                    dict(LD, box=(20, 20, 20), cells=5)),
}
DEFAULT = [r for r in ROWS if r != 'ld_paper']

FRICTION_RECORD = os.path.join(ROOT, 'doc', 'data', 'friction_phi04')
# (case, where the DNS record is: (record directory or None for this study's, row), LD row)
PAIRS = [
    ('phi 0.3, §5.4 set-up', (None, 'dns_phi0.3'), 'ld_phi0.3'),
    ('phi 0.4, §5.4 set-up', (FRICTION_RECORD, 'base'), 'ld'),
    ('phi 0.45, §5.4 set-up', (None, 'dns_phi0.45'), 'ld_phi0.45'),
    ('phi 0.4, paper set-up', (FRICTION_RECORD, 'paperdt2'), 'ld_paper'),
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


def pm(q):
    return '%.3g +- %.2g' % (q['value'], q['error'])


def table(study, rows):
    print('| case | mu_d | model | spheres | ' + ' | '.join(QUANTITIES) +
          ' | eta_r LD/DNS (sigmas) | CPU s per strain |')
    print('|---' * (len(QUANTITIES) + 6) + '|')
    for case, (where, dns_row), ld_row in PAIRS:
        for mu in (0.0, 0.5):
            dns = load(os.path.join(where or study.record_dir, run_name(dns_row, mu), 'summary.json'))
            ld = study.load_record(ld_row, mu)
            for model, s in (('DNS', dns), ('LD', ld)):
                if s is None:
                    print('| %s | %g | %s | (not run) |' % (case, mu, model))
                    continue
                q = s['quantities']
                extra = ''
                if model == 'LD' and dns is not None:
                    a, b = dns['quantities']['eta_r'], q['eta_r']
                    extra = '%.3f (%+.1f)' % (b['value'] / a['value'],
                                              (b['value'] - a['value']) / math.hypot(a['error'], b['error']))
                print('| %s | %g | %s | %s | %s | %s | %.3g |' % (
                    case, mu, model, s['run']['spheres'], ' | '.join(pm(q[k]) for k in QUANTITIES), extra,
                    cpu_per_strain(s)))
    print()
    print('Lees-Edwards against walls in lubrication dynamics (walls: the core; Lees-Edwards: the whole box)')
    print('| mu_d | boundaries | ' + ' | '.join(QUANTITIES) + ' |')
    print('|---' * (len(QUANTITIES) + 2) + '|')
    for mu in (0.0, 0.5):
        for row, label in (('ld', 'walls'), ('ld_le', 'Lees-Edwards')):
            s = study.load_record(row, mu)
            if s is not None:
                print('| %g | %s | %s |' % (mu, label, ' | '.join(pm(s['quantities'][k]) for k in QUANTITIES)))


STUDY = Study('issue 30 model trade', ROWS, BASE, DEFAULT,
              work=os.path.join(ROOT, 'out', 'model_trade'),
              record=os.path.join(ROOT, 'doc', 'data', 'model_trade'), table=table, doc=__doc__)

if __name__ == '__main__':
    sys.exit(STUDY.main())
