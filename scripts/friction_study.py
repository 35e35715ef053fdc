#!/usr/bin/env python3
"""Issue 28: does friction double the viscosity at phi = 0.4? The friction effect (mu_d 0 -> 0.5)
measured while one set-up choice at a time is changed from the doc/VALIDATION.md §5.4 set-up, and
the paper's own set-up (Gallier et al. 2014 §4).

    scripts/friction_study.py [CASE ...] [--mu 0 0.5] [--jobs 2] [--ranks 1] [--hours 0]
                              [--work out/friction_phi04] [--record doc/data/friction_phi04]
                              [--table] [--list] [--rerecord]

CASE names a row of ROWS (default: every row of the sensitivity study, in the order of ROWS), run
at every --mu, or ROW:MU for that one run (e.g. dt5e-4:0.5).
How runs are made, resumed and recorded (doc/data/friction_phi04/<row>_mu<mu>/: deck.nml and
summary.json with "run" and "contacts" objects): fdsusp.study. --rerecord writes the records
of every finished run again. --table prints, from the records, the rows of the sensitivity table: the friction
ratio eta_r(0.5)/eta_r(0), the relative change of |N1|/tau and |N2|/tau, N2/N1 at both mu_d,
each with its error propagated from the block errors.
--extend STRAIN (fdsusp.study) continues finished runs to STRAIN; --table then also prints,
for each extension recorded, its first window against the later one and the slopes of eta_r and
phi_core over 2-strain windows (drift_table).
"""
import json
import math
import os
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp.study import BASE, Study, ratio, split_run_name  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))

# The base (study.BASE): the §5.4 set-up (8a x 20a x 8a Couette cell, a/Delta = 4, bulk phi 0.40
# (seed 1), eps_r 5e-3, full lubrication, dt 2e-3, 2 strains discarded and 20 averaged in 5 blocks)
# with the paper's eps_bar 0.05 instead of 0.1: with implicit contacts the §5.4 choice 0.1 stops at
# mu_d 0.5 (row eb01: the overlap guard, |delta'| > h_r, at strain 7.5).

# One choice changed at a time (issue 28, item 1). The bulk 0.375 puts the core near 0.40: at bulk
# 0.40 the §5.4 cores were 0.4265 (mu_d 0) and 0.4323 (mu_d 0.5), i.e. 1.07-1.08 times the bulk.
ROWS = {
    'base':    ('the §5.4 set-up with eps_bar 0.05', {}),
    'eb01':    ('eps_bar 0.1 (the §5.4 set-up)', dict(eps_bar=0.1)),
    'eb002':   ('eps_bar 0.02', dict(eps_bar=0.02)),
    'explicit': ('explicit contacts, eps_bar 0.1: the §5.4 set-up as run then',
                 dict(eps_bar=0.1, implicit=False)),
    'eb001':   ('eps_bar 0.01, dt 1e-3 (chatter number 0.1)', dict(eps_bar=0.01, dt=1e-3)),
    'eb002dt': ('eps_bar 0.02, dt 5e-4', dict(eps_bar=0.02, dt=5e-4)),
    'core040': ('bulk phi 0.375 (core ~0.40)', dict(phi=0.375)),
    'a5':      ('a/Delta 5', dict(cells=5)),
    'dt5e-4':  ('dt 5e-4 (the paper\'s frictional step)', dict(dt=5e-4)),
    # the paper's figure-16 sweep at the stick number of the base at mu_d 0.5 (4.6): the stick
    # number grows as dt/mu_d, so mu_d 0.1, 0.2, 0.3 take dt 4e-4, 8e-4, 1.2e-3 (run as ROW:MU)
    'dt4e-4':  ('dt 4e-4 (stick number 4.6 at mu_d 0.1)', dict(dt=4e-4)),
    'dt8e-4':  ('dt 8e-4 (stick number 4.6 at mu_d 0.2)', dict(dt=8e-4)),
    'dt1.2e-3': ('dt 1.2e-3 (stick number 4.6 at mu_d 0.3)', dict(dt=1.2e-3)),
    'w12':     ('x, z periods 12a', dict(box=(12, 20, 12))),
    # the figure-16 sweep in the 12a cell (rows w12 at mu_d 0, 0.1 (stick number 23: at mu_d 0.1 the
    # base cell gives the same eta_r at dt 2e-3 and 4e-4), 0.5 and 1), with these at mu_d 0.2, 0.3
    'w12dt8e-4': ('x, z periods 12a, dt 8e-4 (stick number 4.6 at mu_d 0.2)', dict(box=(12, 20, 12), dt=8e-4)),
    'w12dt1.2e-3': ('x, z periods 12a, dt 1.2e-3 (stick number 4.6 at mu_d 0.3)',
                    dict(box=(12, 20, 12), dt=1.2e-3)),
    'w20':     ('x, z periods 20a', dict(box=(20, 20, 20))),
    'w20s2':   ('x, z periods 20a, seed 2', dict(box=(20, 20, 20), seed=2)),
    # issue 28 item 2, the paper's set-up: 20a cube at a/Delta 5 (~760 spheres); dt 1e-3 keeps the
    # stick number at 2.3 (converged) and eta_h within the 5 % that dt 2e-3 costs; 2.4 h per run
    # on 2 ranks (--ranks 2 --jobs 1)
    'paper':   ('the paper\'s set-up: 20a cube, a/Delta 5, dt 1e-3', dict(box=(20, 20, 20), cells=5, dt=1e-3)),
    # the same at the base's dt 2e-3 (stick number 4.6, where base and dt5e-4 agree on the friction
    # ratio, 1.67 and 1.71): both mu_d in one session, two runs of 1 rank side by side (~2 h)
    'paperdt2': ('the paper\'s set-up at dt 2e-3: 20a cube, a/Delta 5', dict(box=(20, 20, 20), cells=5)),
}
SENSITIVITY = [r for r in ROWS if not r.startswith('paper')]   # item 1; 'paper' is item 2


def table(study, rows):
    """The sensitivity table from the records: one line per row with both frictions recorded."""
    print('| row | spheres | phi_core (0 / 0.5) | eta_r (0 -> 0.5) | eta_r ratio | eta_h (0 -> 0.5) '
          '| eta_c (0 -> 0.5) | \\|N1\\|/tau change | \\|N2\\|/tau change | N2/N1 (0 -> 0.5) '
          '| sliding at 0.5 | overlap/h_r (0 / 0.5) |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')

    def pm(q):
        return '%.2f +- %.2f' % (q['value'], q['error'])

    for row in rows:
        s0 = study.load_record(row, 0)
        s1 = study.load_record(row, 0.5)
        note = ''
        if s0 is None and s1 is not None and row != 'base':
            # a row run at mu_d 0.5 only: the frictionless reference is the base's (marked)
            s0 = study.load_record('base', 0)
            note = ' (mu_d 0: the base run)'
        if s0 is None or s1 is None:
            print('| %s: %s | (not finished) |' % (row, ROWS[row][0]))
            continue
        q0, q1 = s0['quantities'], s1['quantities']
        r, re_ = ratio(q0['eta_r'], q1['eta_r'])
        c1, e1 = ratio(q0['N1/tau'], q1['N1/tau'])
        c2, e2 = ratio(q0['N2/tau'], q1['N2/tau'])
        n0, en0 = ratio(q0['N1/tau'], q0['N2/tau'])
        n1, en1 = ratio(q1['N1/tau'], q1['N2/tau'])
        print('| %s: %s | %s | %.4f / %.4f | %s -> %s | **%.3f +- %.3f** | %s -> %s | %s -> %s '
              '| %+.0f +- %.0f %% | %+.0f +- %.0f %% | %.2f +- %.2f -> %.2f +- %.2f | %.0f %% | %.2f / %.2f |'
              % (row, ROWS[row][0] + note, s1['run']['spheres'], q0['phi_core']['value'], q1['phi_core']['value'],
                 pm(q0['eta_r']), pm(q1['eta_r']), r, re_, pm(q0['eta_h']), pm(q1['eta_h']),
                 pm(q0['eta_c']), pm(q1['eta_c']), 100 * (c1 - 1), 100 * e1, 100 * (c2 - 1), 100 * e2,
                 n0, en0, n1, en1, 100 * s1['contacts']['sliding_fraction'],
                 s0['contacts']['largest_overlap_over_h_r_mean'], s1['contacts']['largest_overlap_over_h_r_mean']))


def drift_table(study):
    """The extended runs (records <row>_mu<mu>_to<strain>, fdsusp.study --extend): the first
    window against the later one, and the slope of eta_r and phi_core over the 2-strain windows
    after the first discard (least squares, its standard error from the scatter about the line)."""
    import glob
    import numpy as np
    paths = sorted(glob.glob(os.path.join(study.record_dir, '*_to*', 'summary.json')))
    if not paths:
        return
    print()
    print('| run | spheres | strains | eta_r (first window) | eta_r (later window) | change | phi_core (first / later) '
          '| N2/tau (first / later) | eta_r slope per 10 strains | phi_core slope per 10 strains |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for path in paths:
        with open(path) as f:
            later = json.load(f)
        run = later['run']
        first = study.load_record(*split_run_name(run['continues'])[:2])
        if first is None:
            continue
        q0, q1 = first['quantities'], later['quantities']
        b = later['by_strain']
        x = np.array(b['strain_start']) + 0.5 * b['width']
        keep = x > first['run']['strain_discarded']

        def slope(name):
            y = np.array([np.nan if v is None else v for v in b[name]])[keep]
            xs = x[keep]
            p = np.polyfit(xs, y, 1)
            r = y - np.polyval(p, xs)
            se = math.sqrt((r ** 2).sum() / (len(xs) - 2) / ((xs - xs.mean()) ** 2).sum())
            return 10 * p[0], 10 * se

        d = q1['eta_r']['value'] - q0['eta_r']['value']
        de = math.hypot(q1['eta_r']['error'], q0['eta_r']['error'])
        print('| %s | %s | %g-%g / %g-%g | %.2f +- %.2f | %.2f +- %.2f | %+.2f +- %.2f | %.4f / %.4f | %.3f / %.3f '
              '| %+.2f +- %.2f | %+.4f +- %.4f |'
              % (os.path.basename(os.path.dirname(path)), run['spheres'], first['run']['strain_discarded'],
                 first['run']['strain_discarded'] + first['run']['strain_averaged'], run['strain_discarded'],
                 run['strain_discarded'] + run['strain_averaged'], q0['eta_r']['value'], q0['eta_r']['error'],
                 q1['eta_r']['value'], q1['eta_r']['error'], d, de, q0['phi_core']['value'], q1['phi_core']['value'],
                 q0['N2/tau']['value'], q1['N2/tau']['value'], *slope('eta_r'), *slope('phi_core')))


def tables(study, rows):
    table(study, rows)
    drift_table(study)


STUDY = Study('issue 28 friction study', ROWS, BASE, SENSITIVITY,
              work=os.path.join(ROOT, 'out', 'friction_phi04'),
              record=os.path.join(ROOT, 'doc', 'data', 'friction_phi04'), table=tables, doc=__doc__)

if __name__ == '__main__':
    sys.exit(STUDY.main())
