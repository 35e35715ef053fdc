#!/usr/bin/env python3
"""High-frequency viscosity eta_inf of frozen random hard-sphere configurations against the
paper's Krieger fit (Gallier et al. 2014 §4.3: [eta] = 2.4, phi_m' = 0.68), issue 6.

    scripts/eta_inf.py [--phi 0.1 0.2 0.3 0.4] [--seeds 1] [--box 8 20 8] [--cells 4] [--steps 300]
                       [--jobs 2] [--work out/eta_inf]

For each phi and seed: bin/fdsusp with &particles solid_fraction = phi, motion = 'frozen' (no
contacts, full lubrication), Re = 0.01, dt = 5e-3, backward Euler; the last 50 steps are
averaged. Prints a markdown table of phi_core, eta_inf (core statistics, summary.json), the fit
at phi_core and the difference (doc/VALIDATION.md §5). Runs `jobs` cases at a time on one rank
each.
"""
import argparse
import json
import os
import subprocess
import sys
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import deck  # noqa: E402
from fdsusp.run import ENV, program, run_all  # noqa: E402


ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))


def deck_text(box, cells, phi, seed, discard):
    """The deck of one case (fdsusp.deck): frozen spheres in shear, 5 blocks over the last 0.25 strain."""
    return deck.text([
        ('domain', {'box': box, 'cells_per_radius': cells, 'shear_rate': 1}),
        ('fluid', {'reynolds': 0.01, 'initial_flow': 'shear', 'viscous_theta': 1}),
        ('time', {'dt': 5e-3}),
        ('output', {'directory': 'out', 'progress_every': 50}),
        ('particles', {'solid_fraction': phi, 'seed': seed, 'motion': 'frozen'}),
        ('rheology', {'discard_strain': discard, 'average_strain': 0.25, 'blocks': 5})])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--phi', type=float, nargs='+', default=[0.1, 0.2, 0.3, 0.4])
    ap.add_argument('--seeds', type=int, nargs='+', default=[1])
    ap.add_argument('--box', type=float, nargs=3, default=[8, 20, 8])
    ap.add_argument('--cells', type=int, default=4)
    ap.add_argument('--steps', type=int, default=300)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'eta_inf'))
    ap.add_argument('--table-only', action='store_true', help='tabulate finished runs in --work, run nothing')
    args = ap.parse_args()
    cases = [(phi, seed) for phi in args.phi for seed in args.seeds]
    discard = (args.steps - 50) * 5e-3

    def case_dir(case):
        return os.path.join(args.work, 'phi%g_seed%d' % case)

    def start(case):
        d = case_dir(case)
        os.makedirs(d, exist_ok=True)
        deck.write(os.path.join(d, 'deck.nml'), deck_text(args.box, args.cells, case[0], case[1], discard))
        log = open(os.path.join(d, 'log'), 'w')
        return subprocess.Popen([program('fdsusp'), 'deck.nml'], cwd=d, env=ENV, stdout=log,
                                stderr=subprocess.STDOUT)

    if not args.table_only:
        for case, (status, _) in run_all(cases, start, args.jobs).items():
            if status != 0:
                sys.exit('fdsusp failed in ' + case_dir(case))
    done = []
    for case in cases:
        with open(os.path.join(case_dir(case), 'out', 'summary.json')) as f:
            done.append(case + (json.load(f)['quantities'],))
    print('| phi (packed) | seed | phi_core | gamma_dot_core (flow) | eta_inf | Krieger fit | difference '
          '| (eta - 1)/phi_core | 2.5 + 5.0 phi_core | difference |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    intrinsic = []
    for phi, seed, q in sorted(done):
        pc, eta = q['phi_core']['value'], q['eta_r']['value']
        fit = (1 - pc / 0.68) ** (-2.4 * 0.68)
        dilute = 2.5 + 5.0 * pc
        intrinsic.append(((eta - 1) / pc, dilute))
        print('| %.2f | %d | %.4f | %.4f (%.4f) | %.4f +- %.1e | %.4f | %+.1f %% | %.4f | %.4f | %+.1f %% |' % (
            phi, seed, pc, q['gamma_dot_core']['value'], q.get('gamma_dot_flow', {'value': float('nan')})['value'], eta,
            q['eta_r']['error'], fit, 100 * (eta / fit - 1), (eta - 1) / pc, dilute, 100 * ((eta - 1) / pc / dilute - 1)))
    if len(intrinsic) > 1 and max(args.phi) <= 0.1:   # the dilute-limit summary
        r = [a / b for a, b in intrinsic]
        mean = sum(r) / len(r)
        sd = (sum((x - mean) ** 2 for x in r) / (len(r) - 1)) ** 0.5
        print('\nmean of (eta - 1)/phi over 2.5 + 5.0 phi: %.4f, standard deviation %.4f, standard error %.4f (%d runs)'
              % (mean, sd, sd / len(r) ** 0.5, len(r)))


if __name__ == '__main__':
    main()
