#!/usr/bin/env python3
"""Speed against accuracy (issue 7): one knob at a time around a base setting, for a small
sheared suspension, with the error of each setting against the finest one and its cost per strain.

    scripts/tradeoff.py [--knobs grid dt tolerance lubrication model] [--strain 0.5] [--jobs 2]
                        [--work out/tradeoff] [--table-only] [--plot FILE]

The scene (the same packing at every setting: seed 1, positions in units of a): phi = 0.3 in a
7a x 10a x 7a Couette cell with walls, rough frictional contacts (eps_r = 5e-3, eps_bar = 0.1,
mu_d = 0.5), shear rate 1, started from the linear profile; the core stress (2.5a < y < 7.5a) is
averaged over strains 0.2 to --strain. All runs follow the same deterministic trajectory up to
their discretisation, so the difference of their mean eta_r is the error of the setting, not
sampling noise (over one strain the trajectories do not decorrelate; the block standard error of
each run is printed beside it for scale).

Settings, one knob at a time around the base (a/Delta = 4, dt = 1e-3, tolerances 1e-8 / 1e-10,
lubrication 'full'); the last of each knob is its finest:
  grid (full)    a/Delta = 4, 5 and every further a/Delta with a shipped table
  grid (simple)  the 'simple' model, which needs no table, at a/Delta = 4, 5, 6
  dt             2e-3, 1e-3, 5e-4, 2.5e-4
  tolerance      velocity = pressure relative tolerance 1e-3, 1e-4, 1e-6 (the code's default),
                 then the base's 1e-8 / 1e-10 (the default before this study)
  lubrication    none, simple, full
  model          lubrication dynamics (`&fluid model = 'none'`: no grid, exact pair resistance
                 within 1a), then the resolved fluid (the DNS)
Two errors per setting: against its knob's finest setting (the error that knob causes), and
against the reference, the finest affordable configuration (the largest a/Delta with a table,
dt = 5e-4, tolerances 1e-8 / 1e-10, 'full'), the total error. The figure has one panel of each:
left, every knob against its own finest setting (so a knob's points do not carry another knob's
error, e.g. the grid's in the dt series); right, the total error with the Pareto front over the
distinct configurations. The code's defaults are ringed. Cost = CPU seconds per unit strain of the single-rank run (its own rusage, start-up
included), so runs side by side do not bias it.

Writes a markdown table (doc/BENCHMARKS.md §9), out/tradeoff/tradeoff.json and the error-cost
plot with its Pareto front (doc/figures/tradeoff.png by default).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import deck  # noqa: E402
from fdsusp.resistance import tabled_grids  # noqa: E402
from fdsusp.run import ENV, program, run_all  # noqa: E402


ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
BASE = {'cells': 4, 'dt': 1e-3, 'vtol': 1e-8, 'ptol': 1e-10, 'lub': 'full', 'model': 'resolved'}
# each knob's setting that is the code's default (doc/INPUT.md: cells_per_radius 5, dt 1e-3,
# tolerances 1e-6, 'full', the resolved fluid): ringed in the left panel; in the right one the
# run of the default configuration (a/Delta 5, dt 1e-3, 'full', the default direct solves)
DEFAULTS = {'a/D 5 full', 'dt 0.001', 'tol 1e-06 (default)', 'full', 'DNS (resolved fluid)'}
DEFAULT_RUN = 'a5_dt0.001_tol1e-08-1e-10_full'
BASE_RUN = 'a4_dt0.001_tol1e-08-1e-10_full'


def deck_text(p, average, name):
    """The deck of one run (fdsusp.deck; settings rounded to 6 digits, '%g', as this study always did)."""
    return deck.text([
        ('domain', {'box': (7, 10, 7), 'cells_per_radius': p['cells'], 'y_boundary': 'walls', 'shear_rate': 1}),
        ('fluid', {'model': p['model'], 'reynolds': 0.01, 'initial_flow': 'shear', 'velocity_tolerance': p['vtol'],
                   'pressure_tolerance': p['ptol']}),
        ('time', {'dt': p['dt']}),
        ('output', {'directory': 'out', 'progress_every': 250, 'series_every': 1}),
        ('particles', {'solid_fraction': 0.3, 'seed': 1}),
        ('contact', {'roughness': 5e-3, 'eps_bar': 0.1, 'friction': 0.5}),
        ('lubrication', {'model': p['lub']}),
        ('rheology', {'discard_strain': 0.2, 'average_strain': average, 'blocks': 4}),
        ('run', {'title': 'tradeoff: %s' % name})], float_format='%g')


def settings(knobs):
    """Every run as a dict: name (its directory; identical parameter sets share one run), knob,
    label, parameters and finest (the label of the knob's finest setting). The reference first."""
    grids = tabled_grids(ROOT)
    series = {'reference': [('a/D %d, dt 5e-4, full' % grids[-1], dict(BASE, cells=grids[-1], dt=5e-4))]}
    if 'grid' in knobs:
        series['grid (full)'] = [('a/D %d full' % n, dict(BASE, cells=n)) for n in grids]
        series['grid (simple)'] = [('a/D %d simple' % n, dict(BASE, cells=n, lub='simple')) for n in (4, 5, 6)]
    if 'dt' in knobs:
        series['dt'] = [('dt %g' % dt, dict(BASE, dt=dt)) for dt in (2e-3, 1e-3, 5e-4, 2.5e-4)]
    if 'tolerance' in knobs:
        series['tolerance'] = [('tol %g%s' % (t, ' (default)' * (t == 1e-6)), dict(BASE, vtol=t, ptol=t, krylov=True)) for t in (1e-3, 1e-4, 1e-6)] + \
                              [('tol 1e-8/1e-10', dict(BASE, krylov=True))]
    if 'lubrication' in knobs:
        # the full model is the finest; how short a step 'none' needs is doc/VALIDATION.md §4.3
        series['lubrication'] = [('none', dict(BASE, lub='none')), ('simple', dict(BASE, lub='simple')),
                                 ('full', dict(BASE))]
    if 'model' in knobs:
        # lubrication dynamics: the same deck without the grid (doc/VALIDATION.md §8.7)
        series['model'] = [('LD (no fluid)', dict(BASE, model='none')), ('DNS (resolved fluid)', dict(BASE))]
    out = []
    for knob, members in series.items():
        for label, p in members:
            # the Krylov rows get their own directory: the base shares its tolerances but solves directly
            name = 'a%(cells)d_dt%(dt)g_tol%(vtol)g-%(ptol)g_%(lub)s' % p + ('_ld' if p['model'] == 'none' else '') \
                + ('_krylov' if p.get('krylov') else '')
            out.append({'name': name, 'knob': knob, 'label': label, 'parameters': p,
                        'finest': members[-1][0]})
    return out


def start(work, name, p, strain):
    d = os.path.join(work, name)
    if os.path.exists(d):
        shutil.rmtree(d)
    os.makedirs(d)
    deck.write(os.path.join(d, 'deck.nml'), deck_text(p, strain - 0.2, name))
    log = open(os.path.join(d, 'log'), 'w')
    # the tolerance knob measures the Krylov path (-fluid_solver krylov); the default direct
    # solves are exact and ignore the tolerances
    args = ['-fluid_solver', 'krylov'] if p.get('krylov') else []
    return subprocess.Popen([os.path.join(work, 'fdsusp'), 'deck.nml'] + args, cwd=d, env=ENV,
                            stdout=log, stderr=subprocess.STDOUT)


def result(work, name):
    """(quantities, None) of a finished run, else (None, why): the run's first error line."""
    path = os.path.join(work, name, 'out', 'summary.json')
    if os.path.exists(path):
        with open(path) as f:
            s = json.load(f)
        if s.get('complete'):
            return s['quantities'], None
    why = 'not run'
    log = os.path.join(work, name, 'log')
    if os.path.exists(log):
        errors = [line for line in open(log) if line.startswith('fdsusp: fatal') or
                  line.startswith('fdsusp: input error')]
        # the message up to its advice, without the '|' of |delta'| (the table is markdown)
        why = errors[0][len('fdsusp: '):].split(';')[0].replace('|', '').strip() if errors else 'unfinished'
    return None, why


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--knobs', nargs='+', default=['grid', 'dt', 'tolerance', 'lubrication', 'model'],
                    choices=['grid', 'dt', 'tolerance', 'lubrication', 'model'])
    ap.add_argument('--strain', type=float, default=0.5, help='strain run (the first 0.2 discarded)')
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'tradeoff'))
    ap.add_argument('--table-only', action='store_true', help='tabulate runs already made')
    ap.add_argument('--plot', default=os.path.join(ROOT, 'doc', 'figures', 'tradeoff.png'))
    args = ap.parse_args()
    if args.strain <= 0.2:
        ap.error('--strain must exceed the 0.2 strain discarded')
    runs = settings(args.knobs)
    cpu_path = os.path.join(args.work, 'cpu.json')
    cpu = {}
    if os.path.exists(cpu_path):
        with open(cpu_path) as f:
            cpu = json.load(f)
    params = {}
    for r in runs:
        params.setdefault(r['name'], r['parameters'])
    if not args.table_only:
        os.makedirs(args.work, exist_ok=True)
        shutil.copy2(program('fdsusp'), os.path.join(args.work, 'fdsusp'))

        def report(name, status, seconds):
            cpu[name] = seconds
            with open(cpu_path, 'w') as f:
                json.dump(cpu, f, indent=1)
            print('%-10s status %d, %.0f CPU s' % (name, status, seconds), flush=True)

        run_all(list(params), lambda n: start(args.work, n, params[n], args.strain), args.jobs, report)

    eta = {}
    for name in params:
        q, why = result(args.work, name)
        eta[name] = (q['eta_r']['value'], q['eta_r']['error']) if q else why
    rows = []
    for r in runs:
        finest = next(x['name'] for x in runs if x['knob'] == r['knob'] and x['label'] == r['finest'])
        row = dict(r, eta_r=None, eta_r_error=None, error_knob=None, error=None, failure=None,
                   cpu_per_strain=cpu.get(r['name'], float('nan')) / args.strain)
        if isinstance(eta[r['name']], str):
            row['failure'] = eta[r['name']]
        else:
            row['eta_r'], row['eta_r_error'] = eta[r['name']]
            for key, other in (('error_knob', finest), ('error', runs[0]['name'])):
                if not isinstance(eta[other], str):
                    row[key] = abs(row['eta_r'] / eta[other][0] - 1.0)
        rows.append(row)
    with open(os.path.join(args.work, 'tradeoff.json'), 'w') as f:
        json.dump(rows, f, indent=1)
    print('| knob | setting | eta_r (block s.e.) | error vs the knob\'s finest | error vs reference | CPU s per strain |')
    print('|---|---|---|---|---|---|')
    e = lambda x: '-' if x is None else '%.1e' % x  # noqa: E731
    for r in rows:
        if r['eta_r'] is None:
            print('| %s | %s | failed: %s | | | %.0f |' % (r['knob'], r['label'], r['failure'], r['cpu_per_strain']))
            continue
        print('| %s | %s | %.4f (%.3f) | %s | %s | %.0f |' % (r['knob'], r['label'], r['eta_r'], r['eta_r_error'],
                                                           e(r['error_knob']), e(r['error']), r['cpu_per_strain']))
    if any(r['error'] is not None and r['knob'] != 'reference' for r in rows):
        from fdsusp.plots import plot_front     # matplotlib only when there is something to draw
        plot_front(rows, args.plot, 'cpu_per_strain',
                   {'grid (full)': 'o', 'grid (simple)': 'v', 'dt': 's', 'tolerance': '^', 'lubrication': 'D',
                    'model': 'P'},
                   'cost: CPU seconds per unit strain (1 rank)',
                   'fdsusp speed against accuracy (phi = 0.3, 7a x 10a x 7a, mu_d = 0.5)',
                   default_run=DEFAULT_RUN, base_run=BASE_RUN, base_label='base: a/D 4, dt 1e-3, full, DNS',
                   defaults=DEFAULTS)
        print('plot: %s' % os.path.relpath(args.plot, ROOT))
    return 0


if __name__ == '__main__':
    sys.exit(main())
