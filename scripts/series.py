#!/usr/bin/env python3
"""The series of an fdsusp run, as the program left it: series.h5 and the parts of series.parts/
(doc/DESIGN.md "series.h5: immutable parts, atomic consolidation").

    scripts/series.py OUTDIR            # steps, records and columns of the run's series

A run appends its records as immutable parts and merges them into series.h5 from time to time,
at its end, and when it continues; while a large run goes on, or after it was killed, its newest
records are in series.parts/. read() gives every record once, in step order, as fdsusp would
after consolidating: series.h5's records, then each part's records after the last step so far.

    import series                       # with scripts/ on sys.path
    columns, attributes = series.read('out/demo', ['step', 'core/stress_hydro'])
"""
import argparse
import os
import sys

import h5py
import numpy as np


def _columns(f, names):
    if names is None:
        found = []
        f.visititems(lambda n, o: found.append(n) if isinstance(o, h5py.Dataset) else None)
        names = found
    return {n: f[n][()] for n in names}


def read(outdir, names=None):
    """(columns, attributes) of the run in outdir: columns by name ('step', 'particles/velocity',
    ...; all of them when names is None), each with the records along its first axis; attributes
    of the root (settings written by fdsusp). Parts left by a killed or running run are merged."""
    files = []
    main = os.path.join(outdir, 'series.h5')
    if os.path.exists(main):
        files.append(main)
    parts = os.path.join(outdir, 'series.parts')
    if os.path.isdir(parts):
        files += [os.path.join(parts, p) for p in sorted(os.listdir(parts))
                  if p.endswith('.h5') and not p.startswith('.')]
    if not files:
        raise FileNotFoundError(f'{outdir} holds no series (series.h5 or series.parts/)')
    wanted = None if names is None else list(dict.fromkeys(['step'] + list(names)))
    columns, attributes, last = None, {}, None
    for path in files:
        with h5py.File(path, 'r') as f:
            attributes = attributes or dict(f.attrs)
            got = _columns(f, wanted)
        keep = np.ones(len(got['step']), bool) if last is None else got['step'] > last
        if columns is None:
            columns = {n: v[keep] for n, v in got.items()}
        else:
            for n, v in got.items():
                columns[n] = np.concatenate([columns[n], v[keep]])
        if keep.any():
            last = got['step'][keep][-1]
    if names is not None and 'step' not in names:
        del columns['step']
    return columns, attributes


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('outdir', help='the output directory of a run')
    args = p.parse_args()
    columns, attributes = read(args.outdir)
    steps = columns['step']
    parts = os.path.join(args.outdir, 'series.parts')
    pending = len([x for x in os.listdir(parts) if x.endswith('.h5')]) if os.path.isdir(parts) else 0
    print(f'{args.outdir}: {len(steps)} records, steps {steps[0] if len(steps) else "-"}..'
          f'{steps[-1] if len(steps) else "-"}, {pending} part(s) not yet in series.h5')
    for n in sorted(columns):
        print(f'  {n:36s} {columns[n].shape}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
