#!/usr/bin/python3
"""The paper's pair test in the DNS, against bin/pairtraj (Gallier et al. 2014 JFM §3, figures 3-5;
issue 5): two free rough spheres in a Couette cell, sphere 2 starting at r = x2 - x1 = (start, 0.5a, 0)
from sphere 1, the pair centred in the box, until sphere 2 has passed to x = -start.

    scripts/pair_dns.py [--cases eps0 eps1e-3 eps1e-3_mu03 eps1e-2 eps1e-2_mu03] [--box 20] [--cells 5]
                        [--dt 1e-3] [--start -6] [--reynolds 0.01] [--ranks 1] [--jobs 2]
                        [--hours 0] [--[no-]branch] [--work out/pair_dns] [--figures doc/figures] [--plot-only]

The defaults are the paper's set-up (20a cube with walls in y, a/Delta = 5, dt = 1e-3, start -6a):
a bench of about 2 hours per case on two cores (0.45 s/step). tests/physics/test_pair_dns.py runs a shortened
version through the same functions (fdsusp.pair). Each case is a directory under --work with its decks, log,
the DNS output and pairtraj's CSV; a case with out/checkpoint.h5 continues from it (--hours sets
&run max_wall_hours, so a long study goes on in a later session). The DNS runs for 1.05 times the
pairtraj transit time and, when the pair has not crossed x = -start by then, is continued 10 % of
the transit at a time; it is read up to the crossing.

--branch (the default with several cases): every case follows the same trajectory until its first contact
(lubrication does not depend on the roughness, and friction acts only in contact), so the approach
is run once, as the 'trunk' (the rough eps_r = 1e-2 deck, whose pair touches first; on ranks x jobs
ranks, since it runs alone), up to where
pairtraj's gap first falls below BRANCH_GAP in any case, and every case continues from the trunk's
checkpoint with its own deck. The trunk is refused as a branch point if any contact force acted
in it or its gap fell below BRANCH_GAP / 2. At the paper's set-up this saves about 57 % of the
three later cases (the first contact is at strain 9.3 of 16.1).

Compared (doc/VALIDATION.md §4.4): the relative position y where the pair crosses x = -start (the
"final offset"), the largest |y_DNS - y_pairtraj| at equal x, and N1*, N2* against theta with
N* = 2 (S_xx - S_yy) / S_inf, 2 (S_yy - S_zz) / S_inf, S the stresslet of one sphere (hydrodynamic,
with the lubrication correction, plus contact), S_inf = (20/3) pi eta a^3 gamma_dot, as pairtraj.
Also printed: the DNS pair's relative velocity against the exact free-pair one along its trajectory
(mobility(): radial / tangential errors at four gaps in the approach and the separation), which
tells a steady resistance error from a lag (doc/VALIDATION.md §4.4).
--lees-edwards boundary|centre: the same pair in a Lees-Edwards box, centred on the sliding boundary,
so that one sphere always sees the other through it, or in the box (doc/VALIDATION.md §13).
Needs Debian's python3 with numpy, h5py and matplotlib (the shebang is /usr/bin/python3).
"""
import argparse
import os
import sys

import numpy as np
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp.pair import (CASES, TRUNK_CASE, branch, check_trunk, continuation, deck_steps, load_case,  # noqa: E402
                         mobility, mobility_table, prepare, read_pairtraj, series_steps, start_dns, table,
                         trunk_steps, upto)
from fdsusp.run import run_all  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LABELS = {'eps0': r'$\epsilon_r = 0$', 'eps1e-3': r'$\epsilon_r = 10^{-3}$',
          'eps1e-3_mu03': r'$\epsilon_r = 10^{-3}$, $\mu_d = 0.3$',
          'eps1e-2': r'$\epsilon_r = 10^{-2}$', 'eps1e-2_mu03': r'$\epsilon_r = 10^{-2}$, $\mu_d = 0.3$'}
COLOURS = {'eps0': 'k', 'eps1e-3': 'tab:blue', 'eps1e-3_mu03': 'tab:cyan', 'eps1e-2': 'tab:red',
           'eps1e-2_mu03': 'tab:orange'}


def plot(results, start, figures, tag):
    """Paper figures 3-5 with the DNS (markers) over pairtraj (lines); results: {case: (dns, ref)}."""
    import matplotlib.pyplot as plt
    from fdsusp.plots import theta_axes
    os.makedirs(figures, exist_ok=True)
    names = []
    fig, ax = plt.subplots(figsize=(7, 4))
    arc = np.linspace(0, np.pi, 200)
    ax.fill_between(2 * np.cos(arc), 0, 2 * np.sin(arc), color='0.85', label='excluded, $r < 2a$')
    for k, (case, (dns, ref)) in enumerate(results.items()):
        part, _ = upto(dns, -start)
        ax.plot(ref['x'], ref['y'], '-', color=COLOURS[case], label=LABELS[case])
        # the paper's fig. 3 markers: circles frictionless, open squares mu_d = 0.3 (over the circles)
        style = dict(marker='s', ms=4, mfc='none', mew=0.6) if case.endswith('mu03') else dict(marker='o', ms=2.5)
        ax.plot(part['x'][::5], part['y'][::5], ls='none', color=COLOURS[case],
                label='DNS (markers; lines pairtraj)' if k == 0 else None, **style)
    ax.set_xlim(start, -start)
    ax.set_ylim(0, 2.4)
    ax.set_xlabel('$x/a$')
    ax.set_ylabel('$y/a$')
    ax.set_title('Relative trajectories, DNS against pairtraj (cf. JFM 2014 fig. 3)', fontsize=10)
    ax.legend(fontsize=7, loc='upper left', ncol=2)
    fig.tight_layout()
    names.append(os.path.join(figures, 'pair_dns_%s_trajectories.png' % tag))
    fig.savefig(names[-1], dpi=130)
    plt.close(fig)
    groups = [('normal_stress', [c for c in results if not c.endswith('mu03')], 'frictionless (cf. fig. 4)'),
              ('friction', [c for c in results if c.startswith('eps1e-2')], r'$\epsilon_r = 10^{-2}$ (cf. fig. 5)')]
    for name, cases, title in groups:
        if not cases:
            continue
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
        for k, case in enumerate(cases):
            dns, ref = results[case]
            part, _ = upto(dns, -start)
            for ax, q in zip(axes, ('N1star', 'N2star')):
                ax.plot(ref['theta'], ref[q], '-', color=COLOURS[case], label=LABELS[case])
                ax.plot(part['theta'][::3], part[q][::3], 'o', ms=2.5, color=COLOURS[case],
                        label='DNS (markers; lines pairtraj)' if k == 0 else None)
        theta_axes(axes, fontsize=7)
        fig.suptitle('Pair normal stress differences, DNS against pairtraj, ' + title, fontsize=10)
        fig.tight_layout()
        names.append(os.path.join(figures, 'pair_dns_%s_%s.png' % (tag, name)))
        fig.savefig(names[-1], dpi=130)
        plt.close(fig)
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--cases', nargs='+', default=list(CASES), choices=list(CASES))
    ap.add_argument('--box', type=float, default=20.0)
    ap.add_argument('--cells', type=float, default=5.0)
    ap.add_argument('--dt', type=float, default=1e-3)
    ap.add_argument('--start', type=float, default=-6.0)
    ap.add_argument('--eps-bar', type=float, default=0.05)
    ap.add_argument('--reynolds', type=float, default=0.01)
    ap.add_argument('--theta', type=float, default=0.5, help='viscous_theta of the DNS (0.5 Crank-Nicolson, 1 backward Euler)')
    ap.add_argument('--ranks', type=int, default=1)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--hours', type=float, default=0.0)
    ap.add_argument('--branch', action=argparse.BooleanOptionalAction, default=None,
                    help='run the approach shared by all cases once and branch every case from it before contact '
                         '(default: with more than one case)')
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'pair_dns'))
    ap.add_argument('--figures', default=os.path.join(ROOT, 'doc', 'figures'))
    ap.add_argument('--tag', default='paper', help='figure names: pair_dns_<tag>_*.png')
    ap.add_argument('--plot-only', action='store_true')
    ap.add_argument('--lees-edwards', choices=['boundary', 'centre'],
                    help='a Lees-Edwards box instead of walls, the pair centred on the sliding boundary y = 0 '
                         'or in the box (doc/METHOD.md §3.9)')
    args = ap.parse_args()
    if args.start >= -2:
        ap.error('--start must be below -2 (the spheres would overlap)')
    dirs = {c: os.path.join(os.path.abspath(args.work), c) for c in args.cases}
    if not args.plot_only:
        if args.branch is None:
            args.branch = len(args.cases) > 1

        def prepare_case(c, d, steps=None, branched=args.branch):
            return prepare(c, d, args.box, args.cells, args.dt, args.start, args.eps_bar, args.reynolds,
                           args.theta, args.hours, steps=steps, branched=branched, lees_edwards=args.lees_edwards)

        commands = {c: prepare_case(c, dirs[c]) for c in args.cases}
        if args.branch:
            trunk = os.path.join(os.path.abspath(args.work), 'trunk')
            last = trunk_steps([read_pairtraj(dirs[c]) for c in args.cases], args.dt)
            done = series_steps(trunk)
            if len(done) == 0 or done[-1] < last:
                command = prepare_case(TRUNK_CASE, trunk, steps=last, branched=False)
                # the trunk runs alone: it gets every core the study was given
                status, cpu = run_all(['trunk'], lambda _: start_dns(trunk, command, args.ranks * args.jobs), 1)['trunk']
                print('trunk (to step %d): exit %d, %.0f CPU s' % (last, status, cpu))
                done = series_steps(trunk)
                if status != 0 or len(done) == 0 or done[-1] < last:
                    raise SystemExit('pair_dns.py: the trunk stopped before step %d; run again to continue it' % last)
            check_trunk(trunk, args.box)
            for c in args.cases:
                if not os.path.exists(os.path.join(dirs[c], 'out', 'checkpoint.h5')):
                    branch(trunk, dirs[c], c)
                    commands[c] = prepare_case(c, dirs[c])          # now a branch from the trunk's checkpoint
        pending = list(args.cases)
        while pending:
            results = run_all(pending, lambda c: start_dns(dirs[c], commands[c], args.ranks), args.jobs)
            pending = []
            for c, (status, cpu) in results.items():
                print('%s: exit %d, %.0f CPU s' % (c, status, cpu))
                steps = series_steps(dirs[c])
                if status != 0 or len(steps) == 0 or steps[-1] < deck_steps(dirs[c]):
                    continue            # failed, or stopped by --hours: continued by the next call
                more = continuation(dirs[c], args.box, args.start, args.dt)
                if more is not None:
                    print('%s: not across x = %g by step %d; continued to step %d' % (c, -args.start, steps[-1], more))
                    commands[c] = prepare_case(c, dirs[c], steps=more)
                    pending.append(c)
    data, comparisons, mobilities = {}, {}, {}
    for c in args.cases:
        if not os.path.exists(os.path.join(dirs[c], 'out', 'series.h5')):
            continue
        dns, ref, comparisons[c] = load_case(dirs[c], args.box, args.start)
        mobilities[c] = mobility(dirs[c], args.box)
        data[c] = (dns, ref)
    print(table(comparisons))
    print(mobility_table(mobilities))
    if data:
        print('wrote', ', '.join(plot(data, args.start, args.figures, args.tag)))


if __name__ == '__main__':
    sys.exit(main())
