#!/usr/bin/env bash
# Cost of the particle sub-problem (and of the lubrication links) against the fluid step: 500 free spheres on 100^3 cells, 10
# steps, 1 and 2 ranks; times per step of the PETSc log stages Fluid and Particles (-log_view).
# Called by scripts/bench.sh; results in doc/BENCHMARKS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
mkdir -p build/bench
"$BIN/fdsusp-pack" input/bench/pack500.nml > build/bench/pack500.log 2>&1
for np in 1 2; do
  log=build/bench/particles500_np$np.log
  mpiexec --oversubscribe -n "$np" "$BIN/fdsusp" input/bench/particles500.nml -log_view > "$log" 2>&1
  # stage summary lines: " 2:           Fluid: 1.2345e+01  ..." (time is the first number)
  fluid=$(awk '/^ *[0-9]+: +Fluid:/ {print $3; exit}' "$log")
  part=$(awk '/^ *[0-9]+: +Particles:/ {print $3; exit}' "$log")
  lub=$(awk '/^ *[0-9]+: +Lubrication:/ {print $3; exit}' "$log")
  steps=$(awk '/^steps run:/ {print $3}' "$log")
  printf 'particles500  ranks %d  fluid %8.4f s/step  particles %8.4f s/step  lubrication %8.4f s/step  particles/fluid %5.3f\n' \
    "$np" "$(python3 -c "print($fluid/$steps)")" "$(python3 -c "print($part/$steps)")" \
    "$(python3 -c "print(${lub:-0}/$steps)")" "$(python3 -c "print($part/$fluid)")"
done
