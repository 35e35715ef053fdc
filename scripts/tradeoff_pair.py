#!/usr/bin/env python3
"""Speed against accuracy on the two-sphere pair test (issue 7; the suspension scene is
scripts/tradeoff.py): one knob at a time, the error of the pair's hydrodynamic resistance against
the exact two-sphere theory (bin/fdsusp-resistance: Jeffrey & Onishi 1984, Jeffrey 1992), and the
cost of one resistance evaluation.

    scripts/tradeoff_pair.py [--jobs 2] [--work out/tradeoff_pair] [--table-only] [--plot FILE]

The test: two spheres in a periodic 8a cube at gaps 0.01a (lubrication-dominated: no grid
resolves it) and 0.1a (half a cell at a/Delta = 5), the line of centres d and the pair centre's
sub-cell offset oblique to the grid (those of tests/physics/test_lubrication_resistance.py). Two
runs per gap in resistance mode (velocities imposed, configuration held, steady state by Aitken
extrapolation of the pseudo-time, scripts/calibrate.py): squeeze (+-d, sphere 1 spinning about d)
gives XA11 - XA12 and XC11; sliding (+-e1, sphere 1 spinning about e1) gives YA11 - YA12,
YB11 - YB12 and YC11. The error of a setting is the largest relative error of these five at a
gap (YB11 - YB12, a coupling, relative to the largest resistance of its mode, as in the test).

Knobs around the base (a/Delta = 4, solver tolerances 1e-8 / 1e-10, lubrication 'full'):
  grid (full)    a/Delta of every shipped table (input/lubrication/resolved_a*.h5)
  grid (simple)  a/Delta = 4, 5, 6, 8 with the 'simple' model, which needs no table
  grid (none)    a/Delta = 4, 5, 6, 8 without a correction: what the grid alone resolves
  tolerance      velocity = pressure relative tolerance 1e-3, 1e-4, 1e-6 (the code's default),
                 then the base's 1e-8 / 1e-10 (the default before this study)
  lubrication    none, simple, full at a/Delta = 4
The time step has no knob here: a resistance run is a steady Stokes problem reached in
pseudo-time, whose answer does not depend on dt (doc/METHOD.md §3.3); the suspension scene measures
it. Cost: CPU seconds of one resistance run (its own rusage, start-up included, 100 pseudo-time
steps), the mean over the setting's four runs.

Writes a markdown table (doc/BENCHMARKS.md §9), WORK/tradeoff_pair.json and the error-cost plot
with its Pareto front (doc/figures/tradeoff_pair.png by default).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np

import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import resistance as R, series  # noqa: E402
from fdsusp.plots import plot_front  # noqa: E402
from fdsusp.resistance import pair_scalars, tabled_grids, NAMES  # noqa: E402
from fdsusp.run import ENV, program, run_all  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
PI = math.pi
L = 8.0
GAPS = (0.01, 0.1)
BASE = {'cells': 4, 'tol': None, 'lub': 'full'}          # tol None: DEFAULT_TOL, the base
DEFAULT_TOL = (1e-8, 1e-10)
# Geometry of test_lubrication_resistance: oblique to the grid, off the cell centres.
OFFSET = np.array([0.37, 0.61, 0.13])                     # in cells
D = np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
E1 = np.cross(D, [0.0, 0.0, 1.0]) / np.linalg.norm(np.cross(D, [0.0, 0.0, 1.0]))
E2 = np.cross(D, E1)
FUNCTIONS = ('XA11-XA12', 'XC11', 'YA11-YA12', 'YB11-YB12', 'YC11')


def settings():
    """Every setting as a dict: name (shared by identical parameter sets), knob, label, parameters."""
    series = {
        'grid (full)': [('a/D %d full' % n, dict(BASE, cells=n)) for n in tabled_grids(ROOT)],
        'grid (simple)': [('a/D %d simple' % n, dict(BASE, cells=n, lub='simple')) for n in (4, 5, 6, 8)],
        'grid (none)': [('a/D %d none' % n, dict(BASE, cells=n, lub='none')) for n in (4, 5, 6, 8)],
        'tolerance': [('tol %g%s' % (t, ' (default)' * (t == 1e-6)), dict(BASE, tol=t, krylov=True))
                      for t in (1e-3, 1e-4, 1e-6)] + [('tol 1e-8/1e-10', dict(BASE, krylov=True))],
        'lubrication': [('none', dict(BASE, lub='none')), ('simple', dict(BASE, lub='simple')),
                        ('full', dict(BASE))],
    }
    out = []
    for knob, members in series.items():
        for label, p in members:
            # the Krylov rows get their own runs: the base shares its tolerances but solves directly
            name = 'a%d_%s_tol%s' % (p['cells'], p['lub'], 'default' if p['tol'] is None else '%g' % p['tol']) \
                + ('_krylov' if p.get('krylov') else '')
            out.append({'name': name, 'knob': knob, 'label': label, 'parameters': p})
    return out


def runs_of(name, p):
    """The four resistance runs of a setting: (run name, fdsusp.resistance.deck keywords)."""
    h = 1.0 / p['cells']
    c = np.full(3, L / 2) + OFFSET * h
    vtol, ptol = DEFAULT_TOL if p['tol'] is None else (p['tol'], p['tol'])
    zero = np.zeros(3)
    out = []
    for g in GAPS:
        x1, x2 = c - (1 + g / 2) * D, c + (1 + g / 2) * D
        common = dict(box=(L, L, L), walls=False, shear=0.0, h=h, model=p['lub'], vtol=vtol, ptol=ptol,
                      krylov=p.get('krylov', False))
        out.append(('%s_g%g_A' % (name, g), dict(common, spheres=[(x1, D, D), (x2, -D, zero)])))
        out.append(('%s_g%g_B' % (name, g), dict(common, spheres=[(x1, E1, E1), (x2, -E1, zero)])))
    return out


def start(work, run, kw):
    d = os.path.join(work, run)
    if os.path.exists(d):
        shutil.rmtree(d)
    os.makedirs(d)
    kw = dict(kw)
    # the tolerance knob measures the Krylov path (-fluid_solver krylov); the default direct
    # solves are exact and ignore the tolerances
    args = ['-fluid_solver', 'krylov'] if kw.pop('krylov', False) else []
    R.deck(os.path.join(d, 'deck.nml'), 'out', **kw)
    log = open(os.path.join(d, 'log'), 'w')
    return subprocess.Popen([os.path.join(work, 'fdsusp'), 'deck.nml'] + args, cwd=d, env=ENV,
                            stdout=log, stderr=subprocess.STDOUT)


def steady(work, run):
    """Force and torque on sphere 1 at pseudo-time infinity, and the Aitken estimate's own change
    when the last sample is left out (how far from steady the run ended)."""
    cols = series.read(os.path.join(work, run, 'out'), ['particles/force_hydro', 'particles/torque_hydro'])[0]
    F, Tq = cols['particles/force_hydro'][:, 0], cols['particles/torque_hydro'][:, 0]
    now = np.concatenate([R.aitken(F), R.aitken(Tq)])
    before = np.concatenate([R.aitken(F[:-1]), R.aitken(Tq[:-1])])
    return now[:3], now[3:], np.abs(now - before).max() / max(np.abs(now).max(), 1e-30)


def measured(work, name):
    """{gap: {function: value}} and the worst steady-state drift of the setting's runs."""
    values, drift = {}, 0.0
    for g in GAPS:
        F, Tq, da = steady(work, '%s_g%g_A' % (name, g))
        v = {'XA11-XA12': -F @ D / (6 * PI), 'XC11': -Tq @ D / (8 * PI)}
        F, Tq, db = steady(work, '%s_g%g_B' % (name, g))
        v.update({'YA11-YA12': -F @ E1 / (6 * PI), 'YB11-YB12': Tq @ E2 / (4 * PI), 'YC11': -Tq @ E1 / (8 * PI)})
        values[g] = v
        drift = max(drift, da, db)
    return values, drift


def exact(g):
    ex = dict(zip(NAMES, pair_scalars(g)))
    return {'XA11-XA12': ex['XA11'] - ex['XA12'], 'XC11': ex['XC11'], 'YA11-YA12': ex['YA11'] - ex['YA12'],
            'YB11-YB12': ex['YB11'] - ex['YB12'], 'YC11': ex['YC11']}


def errors(values):
    """{gap: (largest relative error, its function)}."""
    out = {}
    for g in GAPS:
        ex = exact(g)
        worst = (0.0, '')
        for k in FUNCTIONS:
            scale = abs(ex[k]) if k != 'YB11-YB12' else max(abs(ex['YA11-YA12']), abs(ex['YC11']))
            e = abs(values[g][k] - ex[k]) / scale
            if e >= worst[0]:
                worst = (e, k)
        out[g] = worst
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'tradeoff_pair'))
    ap.add_argument('--table-only', action='store_true', help='tabulate runs already made')
    ap.add_argument('--plot', default=os.path.join(ROOT, 'doc', 'figures', 'tradeoff_pair.png'))
    args = ap.parse_args()
    rows = settings()
    params = {}
    for r in rows:
        params.setdefault(r['name'], r['parameters'])
    runs = {run: kw for name, p in params.items() for run, kw in runs_of(name, p)}
    cpu_path = os.path.join(args.work, 'cpu.json')
    cpu = {}
    if os.path.exists(cpu_path):
        with open(cpu_path) as f:
            cpu = json.load(f)
    if not args.table_only:
        os.makedirs(args.work, exist_ok=True)
        shutil.copy2(program('fdsusp'), os.path.join(args.work, 'fdsusp'))
        status = {}

        def report(run, st, seconds):
            cpu[run] = seconds
            status[run] = st
            with open(cpu_path, 'w') as f:
                json.dump(cpu, f, indent=1)
            print('%-32s status %d, %.1f CPU s' % (run, st, seconds), flush=True)

        todo = [run for run in runs if run not in cpu]
        run_all(todo, lambda run: start(args.work, run, runs[run]), args.jobs, report)
        failed = [run for run, st in status.items() if st != 0]
        if failed:
            sys.exit('tradeoff_pair: runs failed: %s (see their log under %s)' % (', '.join(failed), args.work))

    table = []
    for r in rows:
        values, drift = measured(args.work, r['name'])
        err = errors(values)
        mine = [run for run, _ in runs_of(r['name'], r['parameters'])]
        table.append(dict(r, values={str(g): v for g, v in values.items()},
                          error_by_gap={str(g): e for g, e in err.items()},
                          error=max(e for e, _ in err.values()), drift=drift,
                          cpu_per_run=float(np.mean([cpu.get(run, float('nan')) for run in mine]))))
    with open(os.path.join(args.work, 'tradeoff_pair.json'), 'w') as f:
        json.dump(table, f, indent=1)
    print('| knob | setting | largest error, gap 0.01 | largest error, gap 0.1 | XA11-XA12 at 0.01 (exact %.3f) '
          '| CPU s per run |' % exact(0.01)['XA11-XA12'])
    print('|---|---|---|---|---|---|')
    for r in table:
        e1, e2 = r['error_by_gap']['0.01'], r['error_by_gap']['0.1']
        print('| %s | %s | %.1e (%s) | %.1e (%s) | %.3f | %.1f |' % (
            r['knob'], r['label'], e1[0], e1[1], e2[0], e2[1], r['values']['0.01']['XA11-XA12'], r['cpu_per_run']))
    worst = max(r['drift'] for r in table)
    print('largest change of a steady estimate when its last pseudo-time sample is left out: %.1e' % worst)
    plot_front(table, args.plot, 'cpu_per_run',
               {'grid (full)': 'o', 'grid (simple)': 'v', 'grid (none)': 'x', 'tolerance': '^', 'lubrication': 'D'},
               'cost: CPU seconds per resistance run (1 rank)', 'fdsusp pair test: speed against accuracy',
               floor=1e-6, default_run='a5_full_toldefault',
               ylabel='largest relative error against exact theory, gaps 0.01a and 0.1a',
               reference_title='every setting against the exact two-sphere functions')
    print('plot: %s' % os.path.relpath(args.plot, ROOT))
    return 0


if __name__ == '__main__':
    sys.exit(main())
