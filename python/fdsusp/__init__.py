"""fdsusp: the Python side of fdsusp (doc/DESIGN.md "The Python package").

    fdsusp.series       the one reader of a run's series (series.h5 and series.parts/)
    fdsusp.deck         the one writer of namelist decks (and a small reader for checks)
    fdsusp.run          where the programs are (FDSUSP_BIN, the checkout, the install, PATH),
                        running fdsusp, the job pool of the studies
    fdsusp.rheology     the statistics of a run's core region (src/kernels/rheology.F90 redone)
    fdsusp.protocols    the analysis of the &shear protocols: the transient after reversals, the
                        moduli of an oscillation, the stroboscopic displacement between its cycles
    fdsusp.references   the literature fits the paper compares with
    fdsusp.plots        the matplotlib figures (imports matplotlib; nothing else does)
    fdsusp.study        the resumable studies of scripts/friction_study.py and scripts/model_trade.py
    fdsusp.resistance   the exact two-sphere and sphere-wall functions (bin/fdsusp-resistance) and
                        their measurement by fdsusp in resistance mode (scripts/calibrate.py, ...)
    fdsusp.pair         the paper's pair test in the DNS against pairtraj (scripts/pair_dns.py)

The command-line entry points are scripts/*.py (each has --help; they find this package through
scripts/_fdsusp_path.py). Elsewhere, from a checkout without installing: PYTHONPATH=<checkout>/python
(as tests/run_tests.sh sets it); or `pip install -e .` in the checkout; `make install` puts the
package in PREFIX/share/fdsusp/python.
"""
