#!/usr/bin/env bash
# fdsusp test runner, called by `make check`.
# Runs every unit-test program (build/<mode>/tests/test_*) and every test script
# (tests/**/test_*.sh, tests/**/test_*.py). A test passes when it exits 0 and made at least one
# check: its log holds a line 'ok    ...' (what every harness prints per check: mod_unit_checks,
# tests/checks.py, tests/checks.sh; each harness also fails a test with no checks itself, this is
# the runner's own guard, e.g. for a unit program that never calls finish). Each test's output
# goes to build/test-logs/<name>.log; a failing test's log tail is printed. Ends with the line
# "N passed, N failed" and exits non-zero when any test failed or when no test matched PATTERN.
#   usage: run_tests.sh UNIT_BIN_DIR [PATTERN]
set -u
unit_dir=$1
pattern=${2:-}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
export FDSUSP_ROOT=$root
export FDSUSP_BIN=${FDSUSP_BIN:-$root/bin}
# the one way the Python tests find their library (tests/: fdsusp_testlib, checks) and this
# checkout's package fdsusp (python/), ahead of any installed copy (no test sets its own path)
export PYTHONPATH=$root/tests:$root/python${PYTHONPATH:+:$PYTHONPATH}
# the unit-test programs and, one level up, the objects and modules they link (tests that build a
# program against mod_unit_checks)
export FDSUSP_UNIT_DIR=$(cd "$unit_dir" 2>/dev/null && pwd)
# Debian's python3 has numpy and h5py (python3-numpy, python3-h5py); another python3 may be first
# on PATH.
PYTHON=python3
[ -x /usr/bin/python3 ] && PYTHON=/usr/bin/python3
export PYTHON
logdir=$root/build/test-logs
mkdir -p "$logdir"

tests=()
for t in "$unit_dir"/test_*; do [ -x "$t" ] && tests+=("$t"); done
while IFS= read -r t; do tests+=("$t"); done < <(find tests -name 'test_*.sh' -o -name 'test_*.py' | sort)

passed=0; failed=0; failed_names=()
start_all=$(date +%s)
for t in "${tests[@]}"; do
  case "$t" in *"$pattern"*) ;; *) continue ;; esac
  name=$(basename "$t"); name=${name%.*}
  log=$logdir/$name.log
  t0=$(date +%s%N)
  case "$t" in
    *.py) timeout 900 "$PYTHON" "$t" > "$log" 2>&1 ;;
    *.sh) timeout 900 bash "$t" > "$log" 2>&1 ;;
    *)    (cd "$root" && timeout 900 "$t") > "$log" 2>&1 ;;
  esac
  rc=$?
  if [ $rc -eq 0 ] && ! grep -Eq '^[[:space:]]*ok[[:space:]]' "$log"; then
    echo "run_tests.sh: the test exited 0 but made no checks (no 'ok' line)" >> "$log"
    rc=99
  fi
  ms=$(( ($(date +%s%N) - t0) / 1000000 )); dt=$((ms/1000)).$(( (ms%1000)/100 ))
  if [ $rc -eq 0 ]; then
    passed=$((passed+1)); printf 'PASS  %-40s %6ss\n' "$name" "$dt"
  else
    failed=$((failed+1)); failed_names+=("$name")
    printf 'FAIL  %-40s %6ss (exit %d, log %s)\n' "$name" "$dt" "$rc" "${log#$root/}"
    tail -n 15 "$log" | sed 's/^/    | /'
  fi
done
echo "total time $(( $(date +%s) - start_all ))s"
[ ${#failed_names[@]} -gt 0 ] && echo "failed: ${failed_names[*]}"
[ $((passed + failed)) -eq 0 ] && echo "no test matches '$pattern' (a run that tests nothing fails)"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ] && [ $((passed + failed)) -gt 0 ]
