"""Helpers shared by the tests/physics/test_pairtraj_*.py tests (the standard library and fdsusp.run).

run_deck() runs bin/pairtraj (found by fdsusp.run.program: $FDSUSP_BIN, else the bin/ of the
checkout) on a copy of a project deck
with some variables overridden and the CSV redirected to a temporary directory, and returns the
summary printed on stdout and the CSV rows.
"""
import csv
import math
import os
import re
import subprocess
import sys
import tempfile

import checks  # tests/checks.py: the verdict shared by the Python tests
from fdsusp.run import program

# the checkout: $FDSUSP_ROOT (tests/run_tests.sh exports it), else the one holding this file
ROOT = os.environ.get("FDSUSP_ROOT", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
PAIRTRAJ = program("pairtraj")
TMP = tempfile.mkdtemp(prefix="pairtraj_test_")


def deck_text(name, **overrides):
    """Text of input/<name>.nml with variables replaced (value strings as written in a deck)."""
    with open(os.path.join(ROOT, "input", name + ".nml")) as f:
        text = f.read()
    for var, value in overrides.items():
        text, n = re.subn(r"(?im)^(\s*%s\s*=\s*)[^\n!]*" % re.escape(var), r"\g<1>%s" % value, text)
        if n != 1:
            sys.exit("test setup: variable %s not found once in input/%s.nml" % (var, name))
    return text


def run_deck(name, tag=None, **overrides):
    """Run pairtraj on input/<name>.nml with overrides. Returns (summary dict, rows)."""
    tag = tag or name
    csv_path = os.path.join(TMP, tag + ".csv")
    overrides.setdefault("csv_file", "'%s'" % csv_path)
    deck = os.path.join(TMP, tag + ".nml")
    with open(deck, "w") as f:
        f.write(deck_text(name, **overrides))
    proc = subprocess.run([PAIRTRAJ, deck], capture_output=True, text=True)
    if proc.returncode != 0:
        print(proc.stdout, proc.stderr)
        sys.exit("pairtraj failed on %s (exit %d)" % (deck, proc.returncode))
    summary = {}
    for line in proc.stdout.splitlines():
        m = re.match(r"^(\w+) = +([-+0-9.eE]+)", line)
        if m:
            summary[m.group(1)] = float(m.group(2))
    with open(csv_path, newline="") as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    return summary, rows


def interp(xs, ys, x):
    """Linear interpolation of ys(xs) at x (xs increasing)."""
    lo, hi = 0, len(xs) - 1
    if x <= xs[lo]:
        return ys[lo]
    if x >= xs[hi]:
        return ys[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] > x:
            hi = mid
        else:
            lo = mid
    w = (x - xs[lo]) / (xs[hi] - xs[lo])
    return (1 - w) * ys[lo] + w * ys[hi]


class Checker:
    """The pairtraj tests' spelling of the shared verdict (tests/checks.py): check(what, ok, detail)
    records one check, done() exits 1 unless at least one check was made and none failed."""

    def check(self, what, ok, detail=""):
        checks.check(ok, ("%s %s" % (what, detail)).rstrip())

    def done(self):
        checks.finish()
