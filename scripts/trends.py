#!/usr/bin/env python3
"""The paper's friction trends (Gallier et al. 2014 §4.2-4.3, figures 9 and 11), issue 6:
sheared suspensions at phi = 0.3 and 0.4 with mu_d = 0 and 0.5, rheology with block errors.

    scripts/trends.py [--phi 0.3 0.4] [--friction 0 0.5] [--box 8 20 8] [--cells 4] [--dt 2e-3]
                      [--discard 5] [--average 20] [--eps-bar 0.1] [--jobs 2] [--hours 0]
                      [--work out/trends] [--table-only]

Each case is a directory under --work with its deck, log and out/. The script is resumable: a
case with out/summary.json is done; one with out/checkpoint.h5 continues from it (`-restart`);
otherwise it starts. --hours sets &run max_wall_hours, so each run stops cleanly with a
checkpoint and the study can go on in a later session. Runs `jobs` cases at a time on one rank
each, with a copy of bin/fdsusp taken at the first start (a rebuild cannot change a study
half-way). At the end prints a markdown table and the paper's trend checks.

Choices (doc/VALIDATION.md §5.5): dt = 2e-3 keeps the fastest core spheres (5 a gamma_dot at
the core edges) at 0.04 Delta per step, where their stresslet is 1.3 % low (§5.3); eps_bar =
0.1 instead of the paper's 0.05 keeps the explicit Hertz force free of the period-two chatter
seen at this step with 0.05, and the paper found the rheology independent of eps_bar below
~0.2 (its §2.3). Roughness 5e-3 as in the paper's §4.2.
"""
import argparse
import json
import os
import sys
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import deck  # noqa: E402
from fdsusp.run import run_all, start_resumable  # noqa: E402


ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
SHOWN = ['eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'phi_core',
         'gamma_dot_core']


def case_dir(work, phi, mu):
    return os.path.join(work, 'phi%g_mu%g' % (phi, mu))


def start(d, args, phi, mu):
    return start_resumable(d, deck_text(args, phi, mu))[0]


def deck_text(args, phi, mu):
    """The deck of one case (fdsusp.deck)."""
    return deck.text([
        ('domain', {'box': args.box, 'cells_per_radius': args.cells, 'y_boundary': 'walls', 'shear_rate': 1}),
        ('fluid', {'reynolds': 0.01, 'initial_flow': 'shear'}),
        ('time', {'dt': args.dt}),
        ('output', {'directory': 'out', 'progress_every': 500, 'series_every': 5, 'checkpoint_every': 2500}),
        ('particles', {'solid_fraction': phi, 'seed': 1}),
        ('contact', {'roughness': 5e-3, 'eps_bar': args.eps_bar, 'friction': mu}),
        ('lubrication', {'model': 'full'}),
        ('rheology', {'discard_strain': args.discard, 'average_strain': args.average, 'blocks': 5}),
        ('run', {'title': 'trend: phi = %s, mu_d = %s' % (phi, mu), 'max_wall_hours': args.hours})])


def summary(d):
    """The quantities of a finished case (every block complete), else None: a run stopped early
    also writes summary.json, with 'complete' false."""
    path = os.path.join(d, 'out', 'summary.json')
    if not os.path.exists(path):
        return None
    with open(path) as f:
        s = json.load(f)
    return s['quantities'] if s.get('complete') else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--phi', type=float, nargs='+', default=[0.4, 0.3])
    ap.add_argument('--friction', type=float, nargs='+', default=[0.0, 0.5])
    ap.add_argument('--box', type=float, nargs=3, default=[8, 20, 8])
    ap.add_argument('--cells', type=int, default=4)
    ap.add_argument('--dt', type=float, default=2e-3)
    ap.add_argument('--discard', type=float, default=5.0)
    ap.add_argument('--average', type=float, default=20.0)
    ap.add_argument('--eps-bar', type=float, default=0.1)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--hours', type=float, default=0.0)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'trends'))
    ap.add_argument('--table-only', action='store_true', help='tabulate the finished cases, run nothing')
    args = ap.parse_args()
    cases = [(phi, mu) for phi in args.phi for mu in args.friction]
    if not args.table_only:
        waiting = [c for c in cases if summary(case_dir(args.work, *c)) is None]

        def report(case, status, cpu):
            if status != 0:
                print('case phi %g mu %g stopped with status %d (see its log)' % (case + (status,)))

        run_all(waiting, lambda c: start(case_dir(args.work, *c), args, *c), args.jobs, report)
    results = {c: summary(case_dir(args.work, *c)) for c in cases}
    print('| phi | mu_d | ' + ' | '.join(SHOWN) + ' |')
    print('|---|---|' + '---|' * len(SHOWN))
    for (phi, mu), q in results.items():
        if q is None:
            print('| %g | %g | (not finished) |' % (phi, mu))
            continue
        print('| %g | %g | ' % (phi, mu) + ' | '.join('%.4g +- %.2g' % (q[k]['value'], q[k]['error'])
                                                     for k in SHOWN) + ' |')
    # the paper's trends, each with the difference in units of its combined error
    for phi in args.phi:
        a, b = results.get((phi, 0.0)), results.get((phi, 0.5))
        if a is None or b is None:
            continue
        for key, word in [('eta_r', 'raises eta_r'), ('N2/tau', 'raises |N2|/tau'),
                          ('N1/tau', 'lowers |N1|/tau')]:
            va, vb = abs(a[key]['value']), abs(b[key]['value'])
            sigma = (a[key]['error']**2 + b[key]['error']**2)**0.5
            held = vb > va if key != 'N1/tau' else vb < va
            print('phi %g: friction %s: %.4g -> %.4g (%+.1f sigma) %s'
                  % (phi, word, va, vb, (vb - va) / sigma if sigma > 0 else float('nan'),
                     'yes' if held else 'NO'))
        n1, n2 = a['N1/tau'], a['N2/tau']
        sigma = (n1['error']**2 + n2['error']**2)**0.5
        print('phi %g: frictionless N1/tau %.3f +- %.3f, N2/tau %.3f +- %.3f: both negative %s, '
              'difference %.1f sigma' % (phi, n1['value'], n1['error'], n2['value'], n2['error'],
                                         'yes' if n1['value'] < 0 and n2['value'] < 0 else 'NO',
                                         abs(n1['value'] - n2['value']) / sigma if sigma > 0 else float('nan')))
    return 0


if __name__ == '__main__':
    sys.exit(main())
