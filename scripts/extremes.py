#!/usr/bin/env python3
"""The extreme scenes of issue 8 (input/extremes/*.nml): each must run its strains stably, with
the largest rough-contact overlap below half the roughness and finite stresses, or be refused
before any work with a message that states the limit. `make extremes` runs them in full (5
strains each); tests/physics/test_extremes.py runs a short version in make check.

    scripts/extremes.py [SCENE ...] [--steps N] [--jobs 2] [--work out/extremes] [--json FILE]

SCENE: names of input/extremes/*.nml (default: all). --steps overrides each deck's step count.
Prints a markdown table (doc/VALIDATION.md §6); --json writes the same as a list of records.
Verdicts: 'stable' (status 0, every step run, overlap < h_r/2, finite stresses), 'refused'
(input error, status 2, before any step), 'FAILED' (anything else, with the reason).
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp import series  # noqa: E402
from fdsusp.run import ENV, program, run_all  # noqa: E402


ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
SCENES = os.path.join(ROOT, 'input', 'extremes')


def prepare(name, work, steps):
    """The scene's deck in work/name with output to out/ (and the step count replaced)."""
    d = os.path.join(work, name)
    if os.path.exists(d):
        shutil.rmtree(d)
    os.makedirs(d)
    with open(os.path.join(SCENES, name + '.nml')) as f:
        text = f.read()
    text = re.sub(r"directory\s*=\s*'[^']*'", "directory = 'out'", text)
    if steps:
        text = re.sub(r'(?m)^(&time.*)steps\s*=\s*\d+', r'\g<1>steps = %d' % steps, text)
    time_group = re.search(r'^&time.*$', text, re.MULTILINE).group(0)
    requested = int(re.search(r'steps\s*=\s*(\d+)', time_group).group(1))
    dt = float(re.search(r'dt\s*=\s*([0-9.eE+-]+)', time_group).group(1))
    with open(os.path.join(d, 'deck.nml'), 'w') as f:
        f.write(text)
    return d, requested, dt


def verdict(name, d, status, requested, dt):
    log = open(os.path.join(d, 'log')).read()
    record = {'scene': name, 'status': status, 'steps': requested, 'dt': dt, 'strain': None,
              'overlap_over_hr': None, 'finite': None, 'message': '', 'verdict': 'FAILED'}
    warnings = [line[len('fdsusp: warning: '):] for line in log.splitlines() if line.startswith('fdsusp: warning: ')]
    record['warnings'] = warnings
    errors = [line for line in log.splitlines() if line.startswith('fdsusp: ')
              and not line.startswith('fdsusp: warning')]
    if status == 2:
        record['message'] = errors[0] if errors else '(no message)'
        ran = os.path.exists(os.path.join(d, 'out', 'series.h5'))
        record['verdict'] = 'refused' if errors and not ran else 'FAILED'
        return record
    if status != 0:
        record['message'] = errors[0] if errors else 'status %d' % status
        return record
    m = re.search(r'steps run: (\d+)', log)
    done = int(m.group(1)) if m else 0
    record['strain'] = done * dt
    m = re.search(r"largest overlap \|delta'\| over this run\s+([0-9.eE+-]+) h_r", log)
    record['overlap_over_hr'] = float(m.group(1)) if m else 0.0
    out = os.path.join(d, 'out')
    present = series.names(out)
    wanted = [k for k in ('particles/stresslet_hydro', 'particles/stresslet_contact', 'particles/velocity')
              if k in present]
    columns = series.read(out, wanted)[0]       # series.h5 and the records still in series.parts/
    finite = all(np.isfinite(columns[k]).all() for k in wanted)
    record['finite'] = bool(finite)
    reasons = []
    if done != requested:
        reasons.append('%d of %d steps' % (done, requested))
    if record['overlap_over_hr'] >= 0.5:
        reasons.append('overlap %.3f h_r >= 0.5' % record['overlap_over_hr'])
    if not finite:
        reasons.append('non-finite stresses')
    record['verdict'] = 'stable' if not reasons else 'FAILED'
    record['message'] = '; '.join(reasons)
    return record


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scenes', nargs='*')
    ap.add_argument('--steps', type=int, default=0)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--work', default=os.path.join(ROOT, 'out', 'extremes'))
    ap.add_argument('--json')
    ap.add_argument('--table-only', action='store_true',
                    help='judge the scenes already run in --work (status read from their logs), run nothing')
    args = ap.parse_args()
    names = args.scenes or sorted(os.path.basename(p)[:-4] for p in glob.glob(os.path.join(SCENES, '*.nml')))
    # a copy, so that a rebuild during the study cannot change or break it
    args.work = os.path.abspath(args.work)
    os.makedirs(args.work, exist_ok=True)
    binary = os.path.join(args.work, 'fdsusp')
    shutil.copy2(program('fdsusp'), binary)
    waiting, records = list(names), []
    if args.table_only:
        waiting = []
        for name in names:
            d = os.path.join(args.work, name)
            with open(os.path.join(d, 'deck.nml')) as f:
                time_group = re.search(r'^&time.*$', f.read(), re.MULTILINE).group(0)
            log = open(os.path.join(d, 'log')).read()
            status = 2 if 'fdsusp: input error' in log else (0 if re.search(r'^wall time', log, re.M) and
                                                             'fdsusp: fatal' not in log else 1)
            records.append(verdict(name, d, status, int(re.search(r'steps\s*=\s*(\d+)', time_group).group(1)),
                                   float(re.search(r'dt\s*=\s*([0-9.eE+-]+)', time_group).group(1))))
    prepared = {}

    def start(name):
        prepared[name] = prepare(name, args.work, args.steps)
        d = prepared[name][0]
        log = open(os.path.join(d, 'log'), 'w')
        return subprocess.Popen([binary, 'deck.nml'], cwd=d, env=ENV, stdout=log, stderr=subprocess.STDOUT)

    statuses = run_all(waiting, start, args.jobs)
    for name in waiting:
        d, requested, dt = prepared[name]
        records.append(verdict(name, d, statuses[name][0], requested, dt))
    print('| scene | dt | steps (strain) | verdict | largest overlap / h_r | finite | message or warnings |')
    print('|---|---|---|---|---|---|---|')
    for r in records:
        strain = '%d (%.2f)' % (r['steps'], r['strain']) if r['strain'] is not None else '%d' % r['steps']
        overlap = '%.4f' % r['overlap_over_hr'] if r['overlap_over_hr'] is not None else ''
        note = r['message'] or '; '.join(r['warnings'])
        print('| %s | %g | %s | %s | %s | %s | %s |' % (r['scene'], r['dt'], strain, r['verdict'], overlap,
                                                      '' if r['finite'] is None else r['finite'], note))
    if args.json:
        with open(args.json, 'w') as f:
            json.dump(records, f, indent=1)
    return 0 if all(r['verdict'] != 'FAILED' for r in records) else 1


if __name__ == '__main__':
    sys.exit(main())
