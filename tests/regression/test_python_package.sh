#!/usr/bin/env bash
# The pytest suite of the Python package fdsusp (python/tests, on small synthetic files: the series
# reader and its merge of series.parts/, the deck writer and reader, where the programs are, the
# rheology statistics on a series of known block means, the literature fits, the figures, the pair
# study's branch of a series with parts, every script's --help and that no script imports another
# or sets sys.path) run as one test of `make check`: its check is pytest's exit status.
# Needs pytest for the python3 of the tests (Debian's python3-pytest, scripts/install-deps).
. "$(dirname "$0")/../checks.sh"
root=$(cd "$(dirname "$0")/../.." && pwd)
PYTHON=${PYTHON:-python3}
if ! "$PYTHON" -c 'import pytest' 2>/dev/null; then
  check_result 1 "pytest is importable by $PYTHON (install python3-pytest: scripts/install-deps)"
  checks_finish
fi
base=$root/build/test-work/pytest
rm -rf "$base"
mkdir -p "$(dirname "$base")"
out=$("$PYTHON" -m pytest -q -p no:cacheprovider --basetemp="$base" "$root/python/tests" 2>&1)
status=$?
echo "$out"
check_result $status "pytest python/tests: $(echo "$out" | tail -n 1)"
checks_finish
