#!/usr/bin/env python3
"""Issue 46 item 4: the DNS in a Lees-Edwards box against the DNS between walls (its core) and
against lubrication dynamics (LD) in the same Lees-Edwards box, at phi 0.3 and 0.4, mu_d 0 and 0.5,
and what each costs for the same statistical error.

    scripts/le_trade.py [CASE ...] [--mu 0 0.5] [--jobs 1] [--ranks 1] [--hours 0]
                        [--work out/le_trade] [--record doc/data/le_trade] [--table] [--list]

The Lees-Edwards box is 8a x 10a x 8a: the volume of the walls cell's core (8a x 20a x 8a, core
y in [5a, 15a]: doc/VALIDATION.md §8.7), so that both measure about as many spheres. Everything
else is that study's set-up (fdsusp.study BASE: a/Delta 4, eps_r 5e-3, eps_bar 0.05, implicit
contacts, full lubrication, 2 strains discarded and 20 averaged in 5 blocks), except the DNS's
step: in a Lees-Edwards box every sphere is measured, those at the sliding boundary too, which
cross the grid at gamma_dot Ly/2 = 5a per strain, and dt 1e-3 keeps their force density's lag below
1 % of their stresslet (doc/VALIDATION.md §5.3, §13); the walls cell's core edge moves at 5a per
strain too and was run at dt 2e-3 (row dns_le_dt2e-3 measures what that step costs here).
The DNS between walls are the records of doc/data/model_trade (phi 0.3, row dns_phi0.3) and
doc/data/friction_phi04 (phi 0.4, row base). Their spheres gather in the core (phi_core 0.327 and
0.427 at bulk 0.3 and 0.4), so the Lees-Edwards box is also run at those fractions (rows
*_phi0.327, *_phi0.427): the comparison of the two boundary kinds at the same phi. Records: doc/data/le_trade/<row>_mu<mu>/ (deck.nml,
summary.json with the CPU seconds per strain); results: doc/VALIDATION.md §13.1.
"""
import math
import os
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.study import BASE, Study, load, run_name  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
LE = dict(box=(8, 10, 8), boundary='lees-edwards')
ROWS = {
    'dns_le_phi0.3': ('DNS, Lees-Edwards 8a x 10a x 8a, bulk phi 0.3, dt 1e-3', dict(LE, phi=0.3, dt=1e-3)),
    'dns_le_phi0.4': ('DNS, Lees-Edwards 8a x 10a x 8a, bulk phi 0.4, dt 1e-3', dict(LE, phi=0.4, dt=1e-3)),
    'ld_le_phi0.3': ('lubrication dynamics, Lees-Edwards 8a x 10a x 8a, bulk phi 0.3',
                     dict(LE, phi=0.3, model='none')),
    'ld_le_phi0.4': ('lubrication dynamics, Lees-Edwards 8a x 10a x 8a, bulk phi 0.4',
                     dict(LE, phi=0.4, model='none')),
    # the walls cell's core fractions (its spheres gather in the core: bulk 0.3 and 0.4 give 0.327 and
    # 0.427 there), so that the two boundary kinds are compared at the same phi
    'dns_le_phi0.327': ('DNS, Lees-Edwards 8a x 10a x 8a, phi 0.327 (the walls cell\'s core at bulk 0.3), dt 1e-3',
                        dict(LE, phi=0.327, dt=1e-3)),
    'ld_le_phi0.327': ('lubrication dynamics, Lees-Edwards 8a x 10a x 8a, phi 0.327', dict(LE, phi=0.327, model='none')),
    'dns_le_phi0.427': ('DNS, Lees-Edwards 8a x 10a x 8a, phi 0.427 (the walls cell\'s core at bulk 0.4), dt 1e-3',
                        dict(LE, phi=0.427, dt=1e-3)),
    'ld_le_phi0.427': ('lubrication dynamics, Lees-Edwards 8a x 10a x 8a, phi 0.427', dict(LE, phi=0.427, model='none')),
    # at mu_d 0.5 the row above stops at strain 10.4 with an overlap beyond the roughness (eps_bar 0.05
    # is too soft for LD's contacts at 0.427): the same with contacts twice as stiff
    'ld_le_phi0.427_eps0.025': ('lubrication dynamics, Lees-Edwards 8a x 10a x 8a, phi 0.427, eps_bar 0.025',
                                dict(LE, phi=0.427, model='none', eps_bar=0.025)),
    'dns_le_dt2e-3': ('DNS, Lees-Edwards 8a x 10a x 8a, bulk phi 0.4, dt 2e-3 (the walls cell\'s step)',
                      dict(LE, phi=0.4, dt=2e-3)),
}
DEFAULT = ['dns_le_phi0.3', 'ld_le_phi0.3', 'dns_le_phi0.4', 'ld_le_phi0.4', 'dns_le_phi0.327', 'ld_le_phi0.327',
           'dns_le_phi0.427', 'ld_le_phi0.427']
WALLS = {0.3: (os.path.join(ROOT, 'doc', 'data', 'model_trade'), 'dns_phi0.3'),
         0.4: (os.path.join(ROOT, 'doc', 'data', 'friction_phi04'), 'base')}
QUANTITIES = ('eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'phi_core')


def cpu_per_strain(s):
    run = s['run']
    if run.get('cpu_seconds_per_strain'):
        return run['cpu_seconds_per_strain']
    if run.get('wall_time_per_step_s'):
        return run['wall_time_per_step_s'] * run.get('ranks', 1) / run['dt']
    return float('nan')


def pm(q):
    return '%.3g +- %.2g' % (q['value'], q['error'])


def cost_for_error(s, reference):
    """CPU seconds per strain scaled to the statistical error of the reference record: the error of a
    block mean falls as 1/sqrt(strain), so the strain needed for the reference's error in eta_r is
    (own error / reference error)^2 times one's own."""
    e, r = s['quantities']['eta_r']['error'], reference['quantities']['eta_r']['error']
    strain = s['run']['strain_averaged'] * (e / r) ** 2
    return cpu_per_strain(s) * strain


def table(study, rows):
    print('| phi | mu_d | model | spheres | ' + ' | '.join(QUANTITIES) + ' | eta_r / walls DNS (sigmas) | '
          'CPU s per strain | CPU s for the walls DNS\'s error |')
    print('|---' * (len(QUANTITIES) + 7) + '|')
    for phi in (0.3, 0.4):
        for mu in (0.0, 0.5):
            where, row = WALLS[phi]
            walls = load(os.path.join(where, run_name(row, mu), 'summary.json'))
            runs = [('DNS walls (core)', walls)]
            core = {0.3: 0.327, 0.4: 0.427}[phi]
            for r in ('dns_le_phi%g' % phi, 'ld_le_phi%g' % phi, 'dns_le_phi%g' % core, 'ld_le_phi%g' % core) + \
                    (('ld_le_phi0.427_eps0.025', 'dns_le_dt2e-3') if phi == 0.4 else ()):
                runs.append((r, study.load_record(r, mu)))
            for model, s in runs:
                if s is None:
                    print('| %g | %g | %s | (not run) |' % (phi, mu, model))
                    continue
                q = s['quantities']
                extra = ''
                if walls is not None and s is not walls:
                    a, b = walls['quantities']['eta_r'], q['eta_r']
                    extra = '%.3f (%+.1f)' % (b['value'] / a['value'],
                                              (b['value'] - a['value']) / math.hypot(a['error'], b['error']))
                cost = cost_for_error(s, walls) if walls is not None else float('nan')
                print('| %g | %g | %s | %s | %s | %s | %.3g | %.3g |' % (
                    phi, mu, model, s['run']['spheres'], ' | '.join(pm(q[k]) for k in QUANTITIES), extra,
                    cpu_per_strain(s), cost))


STUDY = Study('issue 46 Lees-Edwards trade', ROWS, BASE, DEFAULT,
              work=os.path.join(ROOT, 'out', 'le_trade'),
              record=os.path.join(ROOT, 'doc', 'data', 'le_trade'), table=table, doc=__doc__)

if __name__ == '__main__':
    sys.exit(STUDY.main())
