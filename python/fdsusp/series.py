"""The series of an fdsusp run, as the program left it: series.h5 and the parts of series.parts/
(doc/DESIGN.md "series.h5: immutable parts, atomic consolidation").

A run appends its records as immutable parts and merges them into series.h5 from time to time,
at its end, and when it continues; while a large run goes on, or after it was killed, its newest
records are in series.parts/. read() gives every record once, in step order, as fdsusp would
after consolidating: series.h5's records, then each part's records after the last step so far
(parts in name order).

    from fdsusp import series
    columns, attributes = series.read('out/demo', ['step', 'core/stress_hydro'])

consolidate() is the one writer of a series outside the program: it folds the parts into series.h5
as fdsusp does (for a run branched from another's output, fdsusp.pair.branch).
"""
import os

import h5py
import numpy as np


def _columns(f, names):
    if names is None:
        found = []
        f.visititems(lambda n, o: found.append(n) if isinstance(o, h5py.Dataset) else None)
        names = found
    return {n: f[n][()] for n in names}


def files(outdir):
    """The files holding the run's records, in the order read() merges them: series.h5 (when
    present), then the parts of series.parts/ in name order (hidden ones, being written, aside)."""
    out = []
    main = os.path.join(outdir, 'series.h5')
    if os.path.exists(main):
        out.append(main)
    parts = os.path.join(outdir, 'series.parts')
    if os.path.isdir(parts):
        out += [os.path.join(parts, p) for p in sorted(os.listdir(parts))
                if p.endswith('.h5') and not p.startswith('.')]
    return out


def names(outdir):
    """The columns (dataset paths) of the run's series, as its first file holds them."""
    paths = files(outdir)
    if not paths:
        raise FileNotFoundError(f'{outdir} holds no series (series.h5 or series.parts/)')
    found = []
    with h5py.File(paths[0], 'r') as f:
        f.visititems(lambda n, o: found.append(n) if isinstance(o, h5py.Dataset) else None)
    return found


def pending_parts(outdir):
    """How many parts of series.parts/ are not yet consolidated into series.h5."""
    parts = os.path.join(outdir, 'series.parts')
    return len([x for x in os.listdir(parts) if x.endswith('.h5')]) if os.path.isdir(parts) else 0


def read(outdir, names=None):
    """(columns, attributes) of the run in outdir: columns by name ('step', 'particles/velocity',
    ...; all of them when names is None), each with the records along its first axis; attributes
    of the root (settings written by fdsusp). Parts left by a killed or running run are merged.
    FileNotFoundError when outdir holds no series; KeyError when a column named is missing."""
    paths = files(outdir)
    if not paths:
        raise FileNotFoundError(f'{outdir} holds no series (series.h5 or series.parts/)')
    wanted = None if names is None else list(dict.fromkeys(['step'] + list(names)))
    columns, attributes, last = None, {}, None
    for path in paths:
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


def consolidate(outdir, drop=(), last_step=None):
    """Fold series.parts/ into series.h5 the way fdsusp does (src/io/series.F90): the records read()
    gives, up to last_step when given, without the columns named in drop, written to series.h5.tmp,
    renamed over series.h5, and only then the parts removed, so that a kill at any point leaves a
    series fdsusp continues correctly (leftover parts hold records series.h5 already has, which the
    next consolidation skips; a leftover .tmp it removes). Each column keeps fdsusp's layout:
    extendable along the records, chunks of about 1024 values, its type (the step as integers), so
    that a run continuing here (-restart) appends to it. Returns the number of records kept."""
    columns, attributes = read(outdir)
    keep = np.ones(len(columns['step']), bool) if last_step is None else columns['step'] <= last_step
    main = os.path.join(outdir, 'series.h5')
    tmp = main + '.tmp'
    with h5py.File(tmp, 'w') as f:
        for k, v in attributes.items():
            f.attrs[k] = v
        for n, v in columns.items():
            if n in drop:
                continue
            per_record = v.shape[1:]
            chunk = max(1, 1024 // int(np.prod(per_record, dtype=int)))
            f.create_dataset(n, data=v[keep], maxshape=(None,) + per_record, chunks=(chunk,) + per_record)
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)                    # the data on disk before the name points at it
    finally:
        os.close(fd)
    parts = files(outdir)[1:] if os.path.exists(main) else files(outdir)
    os.replace(tmp, main)
    for part in parts:
        os.remove(part)
    return int(keep.sum())


def settings(attributes):
    """The root attributes as numbers ({name: float}), as the statistics use them."""
    return {k: float(np.ravel(v)[0]) for k, v in attributes.items()}


def describe(outdir):
    """The lines scripts/series.py prints: records, steps, parts pending, and each column's shape."""
    columns, _ = read(outdir)
    steps = columns['step']
    lines = [f'{outdir}: {len(steps)} records, steps {steps[0] if len(steps) else "-"}..'
             f'{steps[-1] if len(steps) else "-"}, {pending_parts(outdir)} part(s) not yet in series.h5']
    lines += [f'  {n:36s} {columns[n].shape}' for n in sorted(columns)]
    return lines
