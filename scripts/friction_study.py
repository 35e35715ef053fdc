#!/usr/bin/env python3
"""Issue 28: does friction double the viscosity at phi = 0.4? The friction effect (mu_d 0 -> 0.5)
measured while one set-up choice at a time is changed from the doc/VALIDATION.md §5.4 set-up, and
the paper's own set-up (Gallier et al. 2014 §4).

    scripts/friction_study.py [CASE ...] [--mu 0 0.5] [--jobs 2] [--ranks 1] [--hours 0]
                              [--work out/friction_phi04] [--record doc/data/friction_phi04]
                              [--table] [--list] [--rerecord]

CASE names a row of ROWS (default: every row of the sensitivity study, in the order of ROWS), run
at every --mu, or ROW:MU for that one run (e.g. dt5e-4:0.5).
Each (row, mu_d) run is a directory <work>/<row>_mu<mu> with its deck, log, out/ and a copy of
bin/fdsusp ($FDSUSP_BIN/fdsusp: point it at a pinned build with a VERSION file beside it) taken at
its first start, so a rebuild cannot change a run half-way. Resumable: a run
whose out/summary.json is complete is done; one with out/checkpoint.h5 continues from it
(`-restart`); otherwise it starts. --hours sets &run max_wall_hours, so a run stops with a
checkpoint in time and the next call continues it (on the same machine: out/ is not in git).

Each finished run is recorded in <record>/<row>_mu<mu>/ as deck.nml and summary.json: fdsusp's
summary with a "run" object added that says what was run without the deck beside it (spheres,
box, a/Delta, bulk phi, mu_d, eps_r, eps_bar, dt, strains discarded and averaged, the fdsusp
commit) and a "contacts" object from series.h5 (contacts, the fraction sliding, overlaps);
--rerecord writes the records of every finished run again. --table prints, from the records, the rows of the sensitivity table: the friction
ratio eta_r(0.5)/eta_r(0), the relative change of |N1|/tau and |N2|/tau, N2/N1 at both mu_d,
each with its error propagated from the block errors.
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from jobpool import run_all, start_resumable  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))

# The base: the §5.4 set-up (8a x 20a x 8a Couette cell, a/Delta = 4, bulk phi 0.40 (seed 1),
# eps_r 5e-3, full lubrication, dt 2e-3, 2 strains discarded and 20 averaged in 5 blocks) with the
# paper's eps_bar 0.05 instead of 0.1: with implicit contacts the §5.4 choice 0.1 stops at mu_d 0.5
# (row eb01: the overlap guard, |delta'| > h_r, at strain 7.5).
BASE = dict(box=(8, 20, 8), cells=4, phi=0.40, seed=1, eps_r=5e-3, eps_bar=0.05, dt=2e-3,
            discard=2.0, average=20.0, blocks=5, min_gap=None, implicit=True)

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
    'w12':     ('x, z periods 12a', dict(box=(12, 20, 12))),
    'w20':     ('x, z periods 20a', dict(box=(20, 20, 20))),
    'w20s2':   ('x, z periods 20a, seed 2', dict(box=(20, 20, 20), seed=2)),
    # issue 28 item 2, the paper's set-up: 20a cube at a/Delta 5 (~760 spheres); dt 1e-3 keeps the
    # stick number at 2.3 (converged) and eta_h within the 5 % that dt 2e-3 costs; 2.4 h per run
    # on 2 ranks (--ranks 2 --jobs 1)
    'paper':   ('the paper\'s set-up: 20a cube, a/Delta 5, dt 1e-3', dict(box=(20, 20, 20), cells=5, dt=1e-3)),
}
SENSITIVITY = [r for r in ROWS if r != 'paper']   # item 1; 'paper' is item 2

DECK = """! issue 28 friction study, row '{row}': {what}; mu_d = {mu} (scripts/friction_study.py)
&domain box = {box}, cells_per_radius = {cells}, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = {dt} /
&output directory = 'out', progress_every = 500, series_every = 5, checkpoint_every = 2500 /
&particles solid_fraction = {phi}, seed = {seed}{packing} /
&contact roughness = {eps_r}, eps_bar = {eps_bar}, friction = {mu}{implicit} /
&lubrication model = 'full' /
&rheology discard_strain = {discard}, average_strain = {average}, blocks = {blocks} /
&run title = 'friction study {row}: mu_d = {mu}', max_wall_hours = {hours} /
"""


def settings(row):
    s = dict(BASE)
    s.update(ROWS[row][1])
    return s


def run_name(row, mu):
    return '%s_mu%g' % (row, mu)


def deck_text(row, mu, hours):
    s = settings(row)
    packing = '' if s['min_gap'] is None else ', packing_min_gap = %g' % s['min_gap']
    return DECK.format(row=row, what=ROWS[row][0], mu=mu, box=', '.join('%g' % b for b in s['box']),
                       cells=s['cells'], dt=s['dt'], phi=s['phi'], seed=s['seed'], packing=packing,
                       eps_r=s['eps_r'], eps_bar=s['eps_bar'], discard=s['discard'],
                       average=s['average'], blocks=s['blocks'], hours=hours,
                       implicit='' if s['implicit'] else ', implicit = .false.')


def load(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def finished(d):
    s = load(os.path.join(d, 'out', 'summary.json'))
    return s is not None and s.get('complete')


def commit_of_binary():
    """The commit the copied program was built from: the file VERSION beside it when the study runs
    a pinned build ($FDSUSP_BIN, so that work in the checkout cannot reach a study half-way),
    else the checkout's."""
    pinned = os.path.join(os.environ.get('FDSUSP_BIN', ''), 'VERSION')
    if os.environ.get('FDSUSP_BIN') and os.path.exists(pinned):
        return open(pinned).read().strip()
    try:
        return subprocess.run(['git', 'describe', '--always', '--dirty'], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'


def start(d, row, mu, args):
    proc, fresh = start_resumable(d, deck_text(row, mu, args.hours), args.ranks)
    if fresh:
        with open(os.path.join(d, 'version'), 'w') as f:
            f.write(commit_of_binary() + '\n')
    return proc


def contact_statistics(series_path, discard_strain):
    """Means over the averaged records (strain > discard) of the contact columns of series.h5:
    contacts between spheres and with the walls, the fraction of them sliding (at the Coulomb
    limit), and the largest overlap of each record in units of h_r."""
    import h5py
    import numpy as np
    with h5py.File(series_path, 'r') as f:
        strain = f['time'][()] * abs(float(np.ravel(f.attrs['shear_rate'])[0]))
        keep = strain > discard_strain
        pair, wall, sliding = (f[k][()][keep] for k in ('contacts_pair', 'contacts_wall', 'contacts_sliding'))
        overlap = f['contact_overlap_over_roughness'][()][keep]
    total = pair + wall
    return {'records': int(keep.sum()), 'pair_contacts': float(pair.mean()), 'wall_contacts': float(wall.mean()),
            'sliding_fraction': float(sliding.sum() / total.sum()) if total.sum() > 0 else 0.0,
            'largest_overlap_over_h_r_mean': float(overlap.mean()), 'largest_overlap_over_h_r_max': float(overlap.max())}


def record(d, row, mu, target, ranks=1):
    """Copy a finished run's deck and summary (with the "run" object) into the record."""
    s = load(os.path.join(d, 'out', 'summary.json'))
    st = settings(row)
    log = open(os.path.join(d, 'log')).read()
    spheres = re.findall(r'(\d+) rigid spheres', log)
    walls = re.findall(r'wall time per step:\s+([0-9.eE+-]+)', log)
    version = open(os.path.join(d, 'version')).read().strip() if os.path.exists(os.path.join(d, 'version')) else 'unknown'
    s['run'] = {
        'study': 'issue 28 friction study (scripts/friction_study.py), row %s: %s' % (row, ROWS[row][0]),
        'spheres': int(spheres[-1]) if spheres else None,
        'box': list(st['box']), 'cells_per_radius': st['cells'], 'y_boundary': 'walls',
        'solid_fraction_bulk': st['phi'], 'seed': st['seed'], 'friction': mu,
        'roughness': st['eps_r'], 'eps_bar': st['eps_bar'], 'implicit_contacts': st['implicit'],
        'dt': st['dt'], 'reynolds': 0.01,
        'lubrication': 'full', 'strain_discarded': st['discard'], 'strain_averaged': st['average'],
        'blocks': st['blocks'], 'fdsusp_version': version,
        'wall_time_per_step_s': float(walls[-1]) if walls else None,
        'ranks': ranks,
    }
    s['contacts'] = contact_statistics(os.path.join(d, 'out', 'series.h5'), st['discard'])
    os.makedirs(target, exist_ok=True)
    shutil.copy2(os.path.join(d, 'deck.nml'), os.path.join(target, 'deck.nml'))
    with open(os.path.join(target, 'summary.json'), 'w') as f:
        json.dump(s, f, indent=1)
        f.write('\n')


def ratio(a, b):
    """b/a with its error from the two relative errors."""
    r = b['value'] / a['value']
    return r, abs(r) * math.hypot(a['error'] / a['value'], b['error'] / b['value'])


def table(rows, record_dir):
    """The sensitivity table from the records: one line per row with both frictions recorded."""
    print('| row | spheres | phi_core (0 / 0.5) | eta_r (0 -> 0.5) | eta_r ratio | eta_h (0 -> 0.5) '
          '| eta_c (0 -> 0.5) | \\|N1\\|/tau change | \\|N2\\|/tau change | N2/N1 (0 -> 0.5) '
          '| sliding at 0.5 | overlap/h_r (0 / 0.5) |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')

    def pm(q):
        return '%.2f +- %.2f' % (q['value'], q['error'])

    for row in rows:
        s0 = load(os.path.join(record_dir, run_name(row, 0), 'summary.json'))
        s1 = load(os.path.join(record_dir, run_name(row, 0.5), 'summary.json'))
        note = ''
        if s0 is None and s1 is not None and row != 'base':
            # a row run at mu_d 0.5 only: the frictionless reference is the base's (marked)
            s0 = load(os.path.join(record_dir, run_name('base', 0), 'summary.json'))
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('rows', nargs='*', default=SENSITIVITY, help='rows of ROWS (default: all)')
    ap.add_argument('--mu', type=float, nargs='+', default=[0.0, 0.5])
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--ranks', type=int, default=1)
    ap.add_argument('--hours', type=float, default=0.0)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'friction_phi04'))
    ap.add_argument('--record', default=os.path.join(ROOT, 'doc', 'data', 'friction_phi04'))
    ap.add_argument('--table', action='store_true', help='print the table from the records, run nothing')
    ap.add_argument('--list', action='store_true', help='print each run\'s deck, run nothing')
    ap.add_argument('--rerecord', action='store_true',
                    help='record every finished run of --work again (after a change of the record), run nothing')
    args = ap.parse_args()
    runs = []
    for spec in args.rows:      # ROW (every --mu) or ROW:MU (that run alone)
        row, _, mu = spec.partition(':')
        if row not in ROWS:
            ap.error('unknown row %r (rows: %s)' % (row, ', '.join(ROWS)))
        runs += [(row, float(mu))] if mu else [(row, m) for m in args.mu]
    args.rows = list(dict.fromkeys(r for r, _ in runs))
    if args.rerecord:
        for name in sorted(os.listdir(args.work)):
            row, _, mu = name.rpartition('_mu')
            d = os.path.join(args.work, name)
            if row in ROWS and finished(d):
                record(d, row, float(mu), os.path.join(args.record, name))
                print('recorded', name)
        return 0
    if args.list:
        for row, mu in runs:
            print(deck_text(row, mu, args.hours))
        return 0
    if not args.table:
        def where(run):
            return os.path.join(args.work, run_name(*run))

        def report(run, status, cpu):
            d = where(run)
            if status != 0:
                print('%s stopped with status %d (see %s/log)' % (run_name(*run), status, d), flush=True)
            elif finished(d):
                record(d, run[0], run[1], os.path.join(args.record, run_name(*run)), args.ranks)
                print('%s finished (%.0f CPU s), recorded' % (run_name(*run), cpu), flush=True)
            else:
                print('%s stopped at its wall-time limit (%.0f CPU s): call again to continue'
                      % (run_name(*run), cpu), flush=True)

        for run in runs:    # finished before, but not yet recorded (e.g. the record was lost)
            target = os.path.join(args.record, run_name(*run))
            if finished(where(run)) and not os.path.exists(os.path.join(target, 'summary.json')):
                record(where(run), run[0], run[1], target, args.ranks)
        waiting = [r for r in runs if not finished(where(r))]
        run_all(waiting, lambda r: start(where(r), r[0], r[1], args), args.jobs, report)
    table([r for r in args.rows], args.record)
    return 0


if __name__ == '__main__':
    sys.exit(main())
