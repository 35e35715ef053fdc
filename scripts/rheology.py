#!/usr/bin/env python3
"""Rheology of fdsusp runs from their series.h5 (doc/RHEOLOGY.md): the command line of
fdsusp.rheology (statistics), fdsusp.plots (figures) and fdsusp.references (literature fits).

    scripts/rheology.py OUTDIR [OUTDIR ...] [--plots DIR] [--compare] [--window D A B] [--json FILE]
    scripts/rheology.py --records SUMMARY.json [...] --plots DIR


For each output directory, recomputes the summary of the core region from series.h5 alone, by
the rules of src/kernels/rheology.F90 (records on the series_every grid after discard_step, `blocks`
blocks of block_steps steps, quantities evaluated on the block means; value from the mean of the
block means, error = standard deviation over the complete blocks (ddof 1) / sqrt(blocks)), and
prints it. --compare: also compare with the run's own summary.json and exit 1 if any number
differs by more than 1e-10 (relative). --window DISCARD AVERAGE BLOCKS: the statistics over
another window than the run's &rheology (strains discarded and averaged, blocks), e.g. a later
window of a run extended from its checkpoint, or the paper's 50 transient strains; steps are
rounded as src/runtime/params.F90 rounds them. --json FILE (one OUTDIR): write the recomputed
summary there, with the keys of fdsusp's summary.json. --plots DIR: PNG figures: per run the core stress time
series, phi(y) and u_x(y), g(theta) and g_c(theta) (paper figs. 6 and 15); over all runs given,
eta_r, N1/tau and N2/tau against phi_core, one series per friction coefficient (paper figs. 9,
11).

--records: the figures of the paper's comparisons from recorded summaries (summary.json with the
"run" object that scripts/friction_study.py adds, e.g. doc/data/friction_phi04/*/summary.json),
no series needed: paper_fig9.png (eta_r, eta_h against phi_core with the Zarraga et al. 2000 fit
and the paper's eta_inf), paper_fig11.png (N1/tau, N2/tau with the Dai et al. 2013 fits),
paper_fig16.png (eta_r, N1/tau, N2/tau against mu_d for each set-up, dt aside, with three or
more frictions: at each mu_d the run of the smallest dt), paper_fig20_22.png (normal viscosity with Morris & Boulay 1999; phi and mu against
I_v with Boyer, Guazzelli & Pouliquen 2011); and from the records of extended runs
(scripts/friction_study.py --extend, with "by_strain") friction_by_strain.png (eta_r, phi_core and
N2/tau over successive strain windows).
"""
import argparse
import json
import os
import sys

import _fdsusp_path  # noqa: F401  (this checkout's python/ on sys.path)
from fdsusp import plots as figures
from fdsusp import rheology


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('outdirs', nargs='*')
    ap.add_argument('--plots', metavar='DIR')
    ap.add_argument('--compare', action='store_true')
    ap.add_argument('--records', nargs='+', metavar='SUMMARY', help='recorded summary.json files')
    ap.add_argument('--window', nargs=3, type=float, metavar=('DISCARD', 'AVERAGE', 'BLOCKS'),
                    help='strains discarded and averaged, and blocks, instead of the run\'s &rheology')
    ap.add_argument('--json', metavar='FILE', help='write the recomputed summary (one OUTDIR)')
    args = ap.parse_args()
    if args.json and len(args.outdirs) != 1:
        ap.error('--json needs exactly one OUTDIR')
    if args.records:
        if not args.plots:
            ap.error('--records needs --plots DIR')
        figures.record_figures(rheology.load_records(args.records), args.plots)
        figures.strain_figure(args.records, args.plots)
        return 0
    if not args.outdirs:
        ap.error('give run output directories or --records')
    runs = []
    status = 0
    for outdir in args.outdirs:
        try:
            a, s = rheology.load(outdir)
            if args.window:
                a = rheology.with_window(a, *args.window)
        except ValueError as e:     # no &rheology in the run; a window of no step
            raise SystemExit(str(e))
        summ = rheology.summarise(a, s)
        if args.json:
            with open(args.json, 'w') as f:
                json.dump(rheology.as_json(a, summ), f, indent=1)
                f.write('\n')
        rheology.print_summary(outdir, summ)
        if args.compare:
            bad = rheology.compare(summ, os.path.join(outdir, 'summary.json'))
            if bad:
                status = 1
                print(f'  summary.json differs ({len(bad)}):', *bad[:10], sep='\n    ')
            else:
                print('  summary.json agrees to 1e-10')
        runs.append((outdir, a, s, summ))
    if args.plots:
        figures.run_figures(runs, args.plots)
    return status


if __name__ == '__main__':
    sys.exit(main())
