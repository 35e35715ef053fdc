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
import glob
import json
import math
import os
import re
import shutil
import subprocess
import sys
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import deck  # noqa: E402
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


def tabled_grids():
    """a/Delta of the shipped full-model tables."""
    found = []
    for path in glob.glob(os.path.join(ROOT, 'input', 'lubrication', 'resolved_a*.h5')):
        m = re.search(r'resolved_a(\d+)\.h5$', path)
        if m:
            found.append(int(m.group(1)))
    return sorted(found)


def settings(knobs):
    """Every run as a dict: name (its directory; identical parameter sets share one run), knob,
    label, parameters and finest (the label of the knob's finest setting). The reference first."""
    grids = tabled_grids()
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


def pareto(points):
    """Indices of the points no other point beats in both cost and error."""
    front = []
    for i, (c, e) in enumerate(points):
        if not any((c2 <= c and e2 <= e) and (c2 < c or e2 < e) for c2, e2 in points):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def plot_front(rows, path, cost, markers, xlabel, title, floor=1e-5, default_run=None, base_run=None, base_label=None,
               ylabel=None, reference_title=None):
    """Two panels of error against cost, one marker and colour per knob. Left: each knob's settings
    against that knob's finest (error_knob), each labelled, the finest itself left out (its error is
    0 by construction). Right: every setting against the reference (error), the Pareto front over
    the distinct configurations, and only the front's points labelled, each run once (base_run, which
    several knobs share, as base_label). Each knob's default setting is ringed on the left, the run
    of the default configuration (default_run) on the right; errors below floor are drawn at floor
    (log axis). Rows without error_knob (the pair test, whose every error is against exact theory)
    get the right panel alone, with ylabel and reference_title."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    per_knob = all('error_knob' in r for r in rows)
    fig, axes = plt.subplots(1, 2 if per_knob else 1, figsize=(14.5 if per_knob else 9, 5.5), sharey=True,
                             squeeze=False)
    axes = axes[0]
    colours = dict(zip(markers, ['C%d' % i for i in range(len(markers))]))

    def draw(ax, key, labelled, ringed):
        placed = []                     # the labels so far, (x, y) of their points
        for knob, marker in markers.items():
            pts = [r for r in rows if r['knob'] == knob and r[key] is not None
                   and not (key == 'error_knob' and r['label'] == r['finest'])]
            for i, r in enumerate(pts):
                x, y = r[cost], max(r[key], floor)
                ax.scatter([x], [y], marker=marker, color=colours[knob], s=45,
                           label=knob if i == 0 else None, zorder=3)
                if ringed(r):
                    ax.scatter([x], [y], marker='o', s=220, facecolors='none', edgecolors='k', lw=1, zorder=2)
                text = labelled(r)
                if text:
                    # above its point, or below when a label already sits near it (within ~15 % in
                    # cost and a factor 1.6 in error), so that neighbours do not overlap
                    near = any(abs(math.log(x / px)) < 0.15 and abs(math.log(y / py)) < 0.5 for px, py in placed) \
                        or r['name'] == base_run          # (its long label would cross the default's ring)
                    placed.append((x, y))
                    ax.annotate(text, (x, y), fontsize=7, color=colours[knob],
                                xytext=(5, -11 if near else 6), textcoords='offset points')
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_xlabel(xlabel)
        ax.grid(True, which='major', lw=0.3)

    if per_knob:
        draw(axes[0], 'error_knob', lambda r: r['label'], lambda r: r['label'] in DEFAULTS)
        axes[0].set_ylabel('|eta_r - eta_r(finest)| / eta_r(finest)')
        axes[0].set_title("each knob against its own finest setting", fontsize=10)
    else:
        axes[0].set_ylabel(ylabel or 'error')
    pts = list({r['name']: r for r in rows if r['knob'] in markers and r['error'] is not None}.values())
    front = pareto([(r[cost], max(r['error'], floor)) for r in pts])
    on_front = {pts[i]['name'] for i in front}
    # one label per distinct run on the front (the base is shared by the grid, dt, lubrication and
    # model knobs: labelled once as such)
    named = set()

    def front_label(r):
        if r['name'] not in on_front or r['name'] in named:
            return None
        named.add(r['name'])
        return base_label if r['name'] == base_run and base_label else r['label']
    draw(axes[-1], 'error', front_label, lambda r: r['name'] == default_run)
    axes[-1].plot([pts[i][cost] for i in front], [max(pts[i]['error'], floor) for i in front], 'k--', lw=1,
                 label='Pareto front')
    axes[-1].set_title(reference_title or 'total error against the reference (finest grid, dt, tolerance)',
                       fontsize=10)
    axes[-1].scatter([], [], marker='o', s=220, facecolors='none', edgecolors='k', label="the code's default")
    axes[-1].legend(fontsize=8, loc='center left', bbox_to_anchor=(1.01, 0.5))
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=120)


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
        plot_front(rows, args.plot, 'cpu_per_strain',
                   {'grid (full)': 'o', 'grid (simple)': 'v', 'dt': 's', 'tolerance': '^', 'lubrication': 'D',
                    'model': 'P'},
                   'cost: CPU seconds per unit strain (1 rank)',
                   'fdsusp speed against accuracy (phi = 0.3, 7a x 10a x 7a, mu_d = 0.5)',
                   default_run=DEFAULT_RUN, base_run=BASE_RUN, base_label='base: a/D 4, dt 1e-3, full, DNS')
        print('plot: %s' % os.path.relpath(args.plot, ROOT))
    return 0


if __name__ == '__main__':
    sys.exit(main())
