#!/usr/bin/env bash
# make bench: the timings recorded in doc/BENCHMARKS.md. Prints one block per case; paste the
# numbers with this command into doc/BENCHMARKS.md. Timings are never asserted by tests.
#   bash scripts/bench.sh            all cases
#   BENCH=couette bash scripts/bench.sh   only the cases whose name contains 'couette'
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
WORK=build/bench
mkdir -p "$WORK"
want() { [[ -z "${BENCH:-}" || "$1" == *"$BENCH"* ]]; }

echo "# fdsusp bench on $(hostname), $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ), commit $(git rev-parse --short HEAD 2>/dev/null || echo none)"

# Couette start-up on 100^3 cells: time per step (20 steps from rest), mean iterations of each
# solve, and one cold multigrid Poisson solve to 1e-8 in the same run; ratio step / cold solve.
couette() {
  local np=$1 log=$WORK/couette100_np$1.log
  mpiexec --oversubscribe -n "$np" "$BIN/fdsusp" input/bench/couette100.nml -bench_cold_poisson \
      -memory_view > "$log" 2>&1
  local cold step its mem
  cold=$(awk '/^bench: cold Poisson/ {print $(NF-3)}' "$log")
  coldits=$(awk '/^bench: cold Poisson/ {print $(NF-1)}' "$log")
  step=$(awk '/^steps run:/ {print $8}' "$log")
  its=$(awk '/^steps run:/ {print $(NF-3)"/"$(NF-2)"/"$(NF-1)"/"$NF}' "$log")
  mem=$(awk '/^Maximum .*process memory/ {print $(NF-4)}' "$log")
  printf 'couette100  ranks %d  step %8.4f s  iterations u/v/w/p %s  cold Poisson %8.4f s (%s its)  step/cold %5.2f  memory (sum over ranks) %s bytes\n' \
      "$np" "$step" "$its" "$cold" "$coldits" "$(python3 -c "print($step/$cold)")" "${mem:-?}"
}
if want couette; then
  couette 1
  couette 2
fi

# Extra bench scripts added by later work (scripts/bench_*.sh), each printing its own lines.
for extra in scripts/bench_*.sh; do
  [[ -e "$extra" ]] || continue
  name=$(basename "$extra" .sh); name=${name#bench_}
  want "$name" && bash "$extra"
done
exit 0
