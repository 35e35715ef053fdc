#!/usr/bin/env python3
"""The series of an fdsusp run, as the program left it: series.h5 and the parts of series.parts/
(doc/DESIGN.md "series.h5: immutable parts, atomic consolidation").

    scripts/series.py OUTDIR            # steps, records and columns of the run's series

The command line of fdsusp.series, the one reader of a run's series: every record once, in step
order, as fdsusp would after consolidating (series.h5's records, then each part's records after
the last step so far). From Python:

    from fdsusp import series
    columns, attributes = series.read('out/demo', ['step', 'core/stress_hydro'])
"""
import argparse
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp import series


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('outdir', help='the output directory of a run')
    args = p.parse_args()
    print('\n'.join(series.describe(args.outdir)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
