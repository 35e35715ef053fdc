#!/usr/bin/env python3
"""Issue 44 item 9: the 1:1.4 mixture (50/50 by volume) in the DNS at phi 0.40-0.50, beside equal
spheres in the DNS and beside the same decks in lubrication dynamics (LD), as doc/VALIDATION.md §8.7
did for equal spheres.

    scripts/mixture_trade.py [CASE ...] [--mu 0 0.5] [--jobs 2] [--hours 0]
                             [--work out/mixture_trade] [--record doc/data/mixture_trade] [--table]

The set-up is §8.7's (fdsusp.study BASE: 8a x 20a x 8a Couette cell, 9a x 20a x 9a for the
mixture (MIXTURE_BOX), the small spheres at a/Delta 4, so the large ones at 5.6, eps_r 5e-3, implicit contacts, full lubrication, seed 1) with
2 strains discarded and 10 averaged in 5 blocks, eps_bar 0.02 (STUDY_BASE). Frictional rows (suffix
_eb002) take dt 8e-4 with it, as §8.7's DNS at phi 0.45 (eps_bar 0.05 reached the overlap guard),
and discard 1.5 strains and average 4.5 in 3 blocks (2.5 times the steps per strain).
Runs are made, resumed and recorded as by fdsusp.study (doc/data/mixture_trade/<row>_mu<mu>/).
--table prints per phi and mu_d: the mixture's DNS and LD, and the equal spheres' DNS (§8.7's
records, and this study's at phi 0.5), with the mixture-to-equal and LD-to-DNS ratios.
"""
import math
import os
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.study import BASE, Study, load, run_name  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
MIXTURE = ((1.0, 0.5), (1.4, 0.5))
LD = dict(model='none')
# frictional rows: 2.5 times the steps, so 1.5 strains discarded and 4.5 averaged in 3 blocks
FRICTIONAL = dict(dt=8e-4, discard=1.5, average=4.5, blocks=3)

# the 1.4 spheres' neighbour search needs periods of at least 2 (2 x 1.4 + 1.4 + 0.2) = 8.8 (the pair
# cut-off is the table's largest gap, 1, in units of the pair's mean radius): the mixture's cell is
# 9a x 20a x 9a, the equal spheres' 8a x 20a x 8a
MIXTURE_BOX = (9, 20, 9)
ROWS = {}
for phi in (0.4, 0.45, 0.5):
    for model, extra in (('dns', {}), ('ld', LD)):
        ROWS['%s_mix_phi%g' % (model, phi)] = (
            '%s, 1:1.4 mixture (50/50 by volume), bulk phi %g' % (model.upper(), phi),
            dict(extra, species=MIXTURE, box=MIXTURE_BOX, phi=phi))
        ROWS['%s_mix_phi%g_eb002' % (model, phi)] = (
            '%s, 1:1.4 mixture, bulk phi %g, eps_bar 0.02, dt 8e-4 (for mu_d 0.5)' % (model.upper(), phi),
            dict(extra, **FRICTIONAL, species=MIXTURE, box=MIXTURE_BOX, phi=phi))
# equal spheres at phi 0.5 (§8.7 has 0.4 and 0.45)
for model, extra in (('dns', {}), ('ld', LD)):
    ROWS['%s_phi0.5' % model] = ('%s, equal spheres, bulk phi 0.5' % model.upper(), dict(extra, phi=0.5))
    ROWS['%s_phi0.5_eb002' % model] = ('%s, equal spheres, bulk phi 0.5, eps_bar 0.02, dt 8e-4' % model.upper(),
                                       dict(extra, **FRICTIONAL, phi=0.5))
# frictional rows with contacts stiff enough for the walls' dense core at phi 0.5 (eps_bar 0.02 stopped
# on the overlap guard, doc/VALIDATION.md §11.3): eps_bar 0.005 (the mixture's effective 0.007), dt
# 2e-4 (stick number 4.6 below the limit 5), 1 strain discarded and 3 averaged in 3 blocks (20000 steps)
STIFF = dict(eps_bar=0.005, dt=2e-4, discard=1.0, average=3.0, blocks=3)
ROWS['dns_mix_phi0.5_eb0005'] = ('DNS, 1:1.4 mixture, bulk phi 0.5, eps_bar 0.005, dt 2e-4 (for mu_d 0.5)',
                                 dict(STIFF, species=MIXTURE, box=MIXTURE_BOX, phi=0.5))
ROWS['dns_phi0.5_eb0005'] = ('DNS, equal spheres, bulk phi 0.5, eps_bar 0.005, dt 2e-4 (for mu_d 0.5)',
                             dict(STIFF, phi=0.5))
DEFAULT = list(ROWS)

# eps_bar 0.02 throughout: the start-up estimate of the largest overlap refuses 0.05 for the
# mixture at phi 0.5 (1.16 h_r; doc/CONTACT.md "The limits of a mixture's contacts"); without
# friction eps_bar does not change the rheology (§5.4), so the frictionless rows keep dt 2e-3
STUDY_BASE = dict(BASE, eps_bar=0.02, discard=2.0, average=10.0, blocks=5)
RECORDS = os.path.join(ROOT, 'doc', 'data')
# the equal spheres' DNS per (phi, mu_d): (record directory, row)
EQUAL_DNS = {
    (0.4, 0.0): ('friction_phi04', 'base'), (0.4, 0.5): ('friction_phi04', 'base'),
    (0.45, 0.0): ('model_trade', 'dns_phi0.45'), (0.45, 0.5): ('model_trade', 'dns_phi0.45_eb002'),
    (0.5, 0.0): ('mixture_trade', 'dns_phi0.5'), (0.5, 0.5): ('mixture_trade', 'dns_phi0.5_eb002'),
}
QUANTITIES = ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'phi_core')


def pm(q):
    return '%.3g +- %.2g' % (q['value'], q['error'])


def compare(a, b):
    """b/a of eta_r and the difference in combined errors."""
    x, y = a['quantities']['eta_r'], b['quantities']['eta_r']
    return '%.3f (%+.1f sigma)' % (y['value'] / x['value'],
                                   (y['value'] - x['value']) / math.hypot(x['error'], y['error']))


def table(study, rows):
    print('| phi | mu_d | run | spheres | ' + ' | '.join(QUANTITIES) + ' | eta_r against the mixture\'s DNS |')
    print('|---' * (len(QUANTITIES) + 5) + '|')
    for phi in (0.4, 0.45, 0.5):
        for mu in (0.0, 0.5):
            suffix = '_eb002' if mu > 0 else ''
            dns = study.load_record('dns_mix_phi%g%s' % (phi, suffix), mu)
            where, row = EQUAL_DNS[phi, mu]
            equal = load(os.path.join(RECORDS, where, run_name(row, mu), 'summary.json'))
            runs = [('mixture, DNS', dns), ('mixture, LD', study.load_record('ld_mix_phi%g%s' % (phi, suffix), mu)),
                    ('equal, DNS (%s %s)' % (where, row), equal)]
            for label, s in runs:
                if s is None:
                    print('| %g | %g | %s | (not run) |' % (phi, mu, label))
                    continue
                q = s['quantities']
                ratio = compare(dns, s) if dns is not None and s is not dns else ''
                print('| %g | %g | %s | %s | %s | %s |' % (phi, mu, label, s['run']['spheres'],
                                                          ' | '.join(pm(q[k]) for k in QUANTITIES), ratio))


STUDY = Study('issue 44 mixture trade', ROWS, STUDY_BASE, DEFAULT,
              work=os.path.join(ROOT, 'out', 'mixture_trade'),
              record=os.path.join(ROOT, 'doc', 'data', 'mixture_trade'), table=table, doc=__doc__)

if __name__ == '__main__':
    sys.exit(STUDY.main())
