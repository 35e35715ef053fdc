"""A resumable study of sheared suspensions in a Couette cell (or a Lees-Edwards box): the machinery
shared by scripts/friction_study.py (issue 28) and scripts/model_trade.py (issue 30), each a table
of rows and its own Study(...).main().

A study is a base set-up (BASE below, overridden per study) and rows, each a name, a sentence and
the settings it changes; each row runs at one or more mu_d. Each (row, mu_d) run is a directory
<work>/<row>_mu<mu> with its deck, log, out/ and a copy of bin/fdsusp ($FDSUSP_BIN/fdsusp: point
it at a pinned build with a VERSION file beside it) taken at its first start, so a rebuild cannot
change a run half-way. A run whose out/summary.json is complete is done; one with out/checkpoint.h5
continues from it (`-restart`); otherwise it starts. --hours sets &run max_wall_hours, so a run
stops with a checkpoint in time and the next call continues it (on the same machine: out/ is not
in git). The CPU seconds of every call are added up in <run>/cpu_seconds.

--extend STRAIN continues finished runs from their last checkpoint to STRAIN, each in a directory
<work>/<row>_mu<mu>_to<STRAIN> of its own (the finished run stays as it was), with a deck that
averages the new strains alone (discard_strain = the finished run's end), so the program starts
its statistics afresh there (doc/INPUT.md &rheology). The record <record>/<row>_mu<mu>_to<STRAIN>/
holds that later window, recomputed by fdsusp.rheology from series.h5 (which the extension
carries on from the start), and "by_strain": eta_r, N1/tau, N2/tau and phi_core over successive
2-strain windows of the whole run, which shows whether the first window had reached steady state.

Each finished run is recorded in <record>/<row>_mu<mu>/ as deck.nml and summary.json: fdsusp's
summary with a "run" object added that says what was run without the deck beside it (model,
spheres, box, boundaries, a/Delta, bulk phi, mu_d, eps_r, eps_bar, dt, strains discarded and
averaged, the fdsusp commit, the cost) and a "contacts" object from series.h5 (contacts, the
fraction sliding, overlaps).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess

from . import deck, rheology
from .run import bin_dir, checkout, run_all, start_resumable

# the checkout (its git commit names a run's program when no pinned build is used); None when installed
ROOT = checkout()

# The doc/VALIDATION.md §5.4 set-up with the paper's eps_bar 0.05: 8a x 20a x 8a Couette cell,
# a/Delta = 4, bulk phi 0.40 (seed 1), eps_r 5e-3, implicit contacts, full lubrication, dt 2e-3,
# 2 strains discarded and 20 averaged in 5 blocks, the resolved fluid, the model's own lubrication
# cut-off (&lubrication outer_cutoff).
# species: None (equal spheres of radius 1) or ((radius, volume share), ...) of a mixture, the
# smallest radius 1 (the unit of length and of cells_per_radius).
BASE = dict(box=(8, 20, 8), cells=4, phi=0.40, seed=1, eps_r=5e-3, eps_bar=0.05, dt=2e-3,
            discard=2.0, average=20.0, blocks=5, min_gap=None, implicit=True,
            model='resolved', boundary='walls', cutoff=None, species=None)

def run_name(row, mu):
    return '%s_mu%g' % (row, mu)


def load(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def split_run_name(name):
    """(row, mu, strain) of a run directory <row>_mu<mu>, or of an extension <row>_mu<mu>_to<strain>
    (strain None otherwise); the inverse of run_name and of --extend's naming."""
    row, _, rest = name.rpartition('_mu')
    mu, _, strain = rest.partition('_to')
    return row, float(mu), float(strain) if strain else None


def finished(d):
    s = load(os.path.join(d, 'out', 'summary.json'))
    return s is not None and s.get('complete')


def ratio(a, b):
    """b/a with its error from the two relative errors."""
    r = b['value'] / a['value']
    return r, abs(r) * math.hypot(a['error'] / a['value'], b['error'] / b['value'])


def commit_of_binary():
    """The commit the copied program was built from: the file VERSION beside it when the study runs
    a pinned build ($FDSUSP_BIN, so that work in the checkout cannot reach a study half-way),
    else the checkout's."""
    programs = bin_dir()                # where program('fdsusp') took the copy from (fdsusp.run)
    pinned = os.path.join(programs, 'VERSION') if programs else ''
    if pinned and os.path.exists(pinned):
        return open(pinned).read().strip()
    if ROOT is None:
        return 'unknown'
    try:
        return subprocess.run(['git', 'describe', '--always', '--dirty'], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'


class Study:
    """rows: {name: (sentence, {setting: value})} over base; title names the study in decks and
    records; default_rows are run when none are named; table(study, rows) prints the result."""

    def __init__(self, title, rows, base, default_rows, work, record, table, doc):
        self.title, self.rows, self.base = title, rows, base
        self.default_rows, self.work, self.record_dir = default_rows, work, record
        self.table, self.doc = table, doc

    def settings(self, row):
        s = dict(self.base)
        s.update(self.rows[row][1])
        return s

    def deck_text(self, row, mu, hours, window=None):
        """The deck of a run (fdsusp.deck); window = (discard, average) strains replaces the row's."""
        s = self.settings(row)
        if window is not None:
            s['discard'], s['average'] = window
        return deck.text([
            ('domain', {'box': s['box'], 'cells_per_radius': s['cells'], 'y_boundary': s['boundary'],
                        'shear_rate': 1}),
            ('fluid', {'model': None if s['model'] == 'resolved' else s['model'], 'reynolds': 0.01,
                       'initial_flow': 'shear'}),
            ('time', {'dt': s['dt']}),
            ('output', {'directory': 'out', 'progress_every': 500, 'series_every': 5, 'checkpoint_every': 2500}),
            ('particles', {'radius': [r for r, _ in s['species']] if s['species'] else None,
                           'volume_share': [v for _, v in s['species']] if s['species'] else None,
                           'solid_fraction': s['phi'], 'seed': s['seed'], 'packing_min_gap': s['min_gap']}),
            ('contact', {'roughness': s['eps_r'], 'eps_bar': s['eps_bar'], 'friction': mu,
                         'implicit': None if s['implicit'] else False}),
            ('lubrication', {'model': 'full', 'outer_cutoff': s['cutoff']}),
            ('rheology', {'discard_strain': s['discard'], 'average_strain': s['average'], 'blocks': s['blocks']}),
            ('run', {'title': '%s %s: mu_d = %s' % (self.title, row, mu), 'max_wall_hours': hours}),
        ], comment="%s, row '%s': %s; mu_d = %s" % (self.title, row, self.rows[row][0], mu))

    def load_record(self, row, mu):
        return load(os.path.join(self.record_dir, run_name(row, mu), 'summary.json'))

    def start(self, d, row, mu, args):
        proc, fresh = start_resumable(d, self.deck_text(row, mu, args.hours), args.ranks)
        if fresh:
            with open(os.path.join(d, 'version'), 'w') as f:
                f.write(commit_of_binary() + '\n')
        return proc

    def start_extension(self, d, row, mu, strain, work, args):
        """The finished run (row, mu) of work continued in d from its last checkpoint to strain."""
        if not os.path.exists(os.path.join(d, 'fdsusp')):
            source = os.path.join(work, run_name(row, mu))
            if not finished(source):
                raise SystemExit('--extend: %s has not finished (its checkpoint is where the extension starts)' % source)
            os.makedirs(os.path.join(d, 'out'), exist_ok=True)
            for f in ('out/checkpoint.h5', 'out/series.h5', 'fdsusp', 'version'):
                shutil.copy2(os.path.join(source, f), os.path.join(d, f))
        end = self.end_strain(row)
        proc, _ = start_resumable(d, self.deck_text(row, mu, args.hours, window=(end, strain - end)), args.ranks)
        return proc

    def end_strain(self, row):
        s = self.settings(row)
        return s['discard'] + s['average']

    def record_extension(self, d, row, mu, strain, target, ranks=1):
        """Record an extension: its later window and the whole run's 2-strain windows, both
        recomputed from series.h5 (the program's own summary.json is not used: a program older
        than the restart rule of 2026-11-26 mixes the finished run's accumulators into it)."""
        st = self.settings(row)
        end = self.end_strain(row)
        a, series = rheology.load(os.path.join(d, 'out'))
        a = rheology.with_window(a, end, strain - end, st['blocks'])
        s = rheology.as_json(a, rheology.summarise(a, series))
        s['run'] = self.run_object(d, row, mu, ranks, end, strain - end)
        s['run']['continues'] = run_name(row, mu)
        if s['run']['cpu_seconds']:     # the extension's own cost, over the strains it ran
            s['run']['cpu_seconds_per_strain'] = s['run']['cpu_seconds'] / (strain - end)
        s['contacts'] = rheology.contact_statistics(os.path.join(d, 'out'), end)
        s['by_strain'] = rheology.strain_windows(a, series, 2.0, ['eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'phi_core'])
        self.write_record(d, target, s)

    def write_record(self, d, target, s):
        os.makedirs(target, exist_ok=True)
        shutil.copy2(os.path.join(d, 'deck.nml'), os.path.join(target, 'deck.nml'))
        with open(os.path.join(target, 'summary.json'), 'w') as f:
            json.dump(s, f, indent=1)
            f.write('\n')

    def record(self, d, row, mu, target, ranks=1):
        """Copy a finished run's deck and summary (with the "run" object) into the record."""
        s = load(os.path.join(d, 'out', 'summary.json'))
        st = self.settings(row)
        s['run'] = self.run_object(d, row, mu, ranks, st['discard'], st['average'])
        s['contacts'] = rheology.contact_statistics(os.path.join(d, 'out'), st['discard'])
        self.write_record(d, target, s)

    def run_object(self, d, row, mu, ranks, discard, average):
        """What a run was, without its deck: set-up, window, program and cost."""
        st = self.settings(row)
        log = open(os.path.join(d, 'log')).read()
        spheres = [int(n) for n in re.findall(r'(\d+) rigid spheres', log)]
        walls = re.findall(r'wall time per step:\s+([0-9.eE+-]+)', log)
        version = open(os.path.join(d, 'version')).read().strip() if os.path.exists(os.path.join(d, 'version')) else 'unknown'
        cpu_file = os.path.join(d, 'cpu_seconds')
        cpu = sum(float(x) for x in open(cpu_file).read().split()) if os.path.exists(cpu_file) else None
        strain = discard + average
        return {
            'study': '%s, row %s: %s' % (self.title, row, self.rows[row][0]),
            'fluid_model': st['model'], 'spheres': spheres[-1] if spheres else None,
            'box': list(st['box']), 'cells_per_radius': st['cells'], 'y_boundary': st['boundary'],
            'solid_fraction_bulk': st['phi'], 'seed': st['seed'], 'friction': mu,
            'species': [{'radius': r, 'volume_share': v} for r, v in st['species']] if st['species'] else None,
            'roughness': st['eps_r'], 'eps_bar': st['eps_bar'], 'implicit_contacts': st['implicit'],
            'dt': st['dt'], 'reynolds': 0.01,
            'lubrication': 'full', 'lubrication_outer_cutoff': st['cutoff'], 'strain_discarded': discard, 'strain_averaged': average,
            'blocks': st['blocks'], 'fdsusp_version': version,
            'wall_time_per_step_s': float(walls[-1]) if walls else None,
            'ranks': ranks,
            # CPU seconds over every call (the runs' own rusage, whatever ran beside them)
            'cpu_seconds': cpu, 'cpu_seconds_per_strain': cpu / strain if cpu else None,
        }

    def main(self, argv=None):
        ap = argparse.ArgumentParser(description=self.doc, formatter_class=argparse.RawDescriptionHelpFormatter)
        ap.add_argument('rows', nargs='*', default=self.default_rows, help='rows (default: %(default)s)')
        ap.add_argument('--mu', type=float, nargs='+', default=[0.0, 0.5])
        ap.add_argument('--jobs', type=int, default=2)
        ap.add_argument('--ranks', type=int, default=1)
        ap.add_argument('--hours', type=float, default=0.0)
        ap.add_argument('--work', default=self.work)
        ap.add_argument('--record', default=self.record_dir)
        ap.add_argument('--extend', type=float, metavar='STRAIN',
                        help='continue the finished runs named to STRAIN, each in <run>_to<STRAIN> (module doc)')
        ap.add_argument('--table', action='store_true', help='print the table from the records, run nothing')
        ap.add_argument('--list', action='store_true', help='print each run\'s deck, run nothing')
        ap.add_argument('--rerecord', action='store_true',
                        help='record every finished run of --work again (after a change of the record), run nothing')
        args = ap.parse_args(argv)
        self.record_dir = args.record
        runs = []
        for spec in args.rows:      # ROW (every --mu) or ROW:MU (that run alone)
            row, _, mu = spec.partition(':')
            if row not in self.rows:
                ap.error('unknown row %r (rows: %s)' % (row, ', '.join(self.rows)))
            runs += [(row, float(mu))] if mu else [(row, m) for m in args.mu]
        rows = list(dict.fromkeys(r for r, _ in runs))
        if args.rerecord:
            for name in sorted(os.listdir(args.work)):
                d = os.path.join(args.work, name)
                if name.rpartition('_mu')[0] in self.rows and finished(d):
                    row, mu, strain = split_run_name(name)
                    if strain:
                        self.record_extension(d, row, mu, strain, os.path.join(args.record, name))
                    else:
                        self.record(d, row, mu, os.path.join(args.record, name))
                    print('recorded', name)
            return 0
        extend = args.extend
        if extend:
            for row, mu in runs:
                if extend <= self.end_strain(row):
                    ap.error('--extend %g: %s ends at strain %g already' % (extend, run_name(row, mu), self.end_strain(row)))
        if args.list:
            for row, mu in runs:
                end = self.end_strain(row)
                print(self.deck_text(row, mu, args.hours, window=(end, extend - end) if extend else None))
            return 0

        def name_of(run):
            return run_name(*run) + ('_to%g' % extend if extend else '')

        def record(run, ranks):
            d, target = where(run), os.path.join(args.record, name_of(run))
            if extend:
                self.record_extension(d, run[0], run[1], extend, target, ranks)
            else:
                self.record(d, run[0], run[1], target, ranks)

        def start(run):
            if extend:
                return self.start_extension(where(run), run[0], run[1], extend, args.work, args)
            return self.start(where(run), run[0], run[1], args)

        def where(run):
            return os.path.join(args.work, name_of(run))

        if not args.table:

            def report(run, status, cpu):
                d = where(run)
                with open(os.path.join(d, 'cpu_seconds'), 'a') as f:
                    f.write('%.1f\n' % cpu)
                if status != 0:
                    print('%s stopped with status %d (see %s/log)' % (name_of(run), status, d), flush=True)
                elif finished(d):
                    record(run, args.ranks)
                    print('%s finished (%.0f CPU s), recorded' % (name_of(run), cpu), flush=True)
                else:
                    print('%s stopped at its wall-time limit (%.0f CPU s): call again to continue'
                          % (name_of(run), cpu), flush=True)

            for run in runs:    # finished before, but not yet recorded (e.g. the record was lost)
                if finished(where(run)) and not os.path.exists(os.path.join(args.record, name_of(run), 'summary.json')):
                    record(run, args.ranks)
            waiting = [r for r in runs if not finished(where(r))]
            run_all(waiting, start, args.jobs, report)
        self.table(self, rows)
        return 0
