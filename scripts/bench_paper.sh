#!/usr/bin/env bash
# The paper's scene as a bench (issue 7): input/bench_paper.nml (100^3 cells, ~764 spheres,
# phi = 0.4, mu_d = 0.5, full lubrication, 50 steps of dt = 5e-4, a series record every step) on 1
# and 2 ranks. For each: wall time per step of the time loop, the PETSc log stages per step,
# the mean solver iterations, one cold multigrid Poisson solve on the same grid in the same run
# (-bench_cold_poisson) and the ratio step / cold solve, the largest resident memory summed over
# ranks (-memory_view); then the parallel efficiency from 1 to 2 ranks and the log events inside
# the stages (FDGeometry ... FFTSolve). s/step is the median over the last half of the run (from
# series.h5), beside the loop's mean. Targets of issue 31: step/cold <= 0.5, <= 0.4 s/step on 2
# cores, efficiency >= 80 %, memory <= 2 GB. Results: doc/BENCHMARKS.md §8.
#   bash scripts/bench_paper.sh                  both rank counts
#   RANKS="2" STEPS=10 bash scripts/bench_paper.sh
#   BIN=/path/to/other/bin bash scripts/bench_paper.sh   (before/after comparisons)
#   FLUID="velocity_tolerance = 1e-6" bash scripts/bench_paper.sh   (extra &fluid settings)
#   OPTIONS="-fluid_extrapolate 0" bash scripts/bench_paper.sh   (extra command-line options)
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
RANKS=${RANKS:-"1 2"}
STEPS=${STEPS:-50}
FLUID=${FLUID:+, $FLUID}
TAG=${TAG:-paper}
OPTIONS=${OPTIONS:-}
mkdir -p build/bench
stage() { awk -v s="$1" '$2 == s":" {print $3; exit}' "$2"; }
event() { awk -v e="$1" '$1 == e {t += $4} END {print t + 0}' "$2"; }
# Debian's python3 has h5py (another python3 may be first on PATH)
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
declare -A per_step
events="FDGeometry FDCarryLambda FDMoments ParticleSolve FDUpdate FFTSolve"
eventrows=""
printf '| ranks | s/step (median, last half) | mean | Fluid | Particles | Lubrication | Contacts | Output | its u/v/w/p | cold Poisson s (its) | step/cold | memory GB |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for np in $RANKS; do
  deck=build/bench/${TAG}_np$np.nml
  sed -e "s|directory = '[^']*'|directory = 'build/bench/${TAG}_np$np'|" \
      -e "s|steps = [0-9]*|steps = $STEPS|" -e "s|initial_flow = 'shear'|initial_flow = 'shear'$FLUID|" \
      input/bench_paper.nml > "$deck"
  log=build/bench/${TAG}_np$np.log
  mpiexec --oversubscribe -n "$np" "$BIN/fdsusp" "$deck" -log_view -memory_view -bench_cold_poisson $OPTIONS > "$log" 2>&1
  steps=$(awk '/^steps run:/ {print $3}' "$log")
  step=$(awk '/^steps run:/ {print $8}' "$log")
  its=$(awk '/^steps run:/ {print $(NF-3)"/"$(NF-2)"/"$(NF-1)"/"$NF}' "$log")
  cold=$(awk '/^bench: cold Poisson/ {print $(NF-3)}' "$log")
  coldits=$(awk '/^bench: cold Poisson/ {print $(NF-1)}' "$log")
  mem=$(awk '/^Maximum .*process memory/ {print $(NF-4); exit}' "$log")
  # the median wall time per step over the last half of the records (series_every = 1)
  median=$($PY -c "
import h5py, numpy as np
t = np.array(h5py.File('build/bench/${TAG}_np$np/series.h5', 'r')['wall_time'])
d = np.diff(t)[len(t) // 2:]
print('%.4f' % np.median(d))")
  row="| $np | $median | $step"
  for s in Fluid Particles Lubrication Contacts Output; do
    t=$(stage "$s" "$log")
    row="$row | $(python3 -c "print('%.3f' % (${t:-0} / $steps))")"
  done
  row="$row | $its | $cold ($coldits) | $(python3 -c "print('%.2f' % ($median / $cold))") | $(python3 -c "print('%.2f' % (${mem:-0} / 1e9))") |"
  echo "$row"
  per_step[$np]=$median
  erow="| $np"
  for e in $events; do
    erow="$erow | $(python3 -c "print('%.3f' % ($(event "$e" "$log") / $steps))")"
  done
  eventrows="$eventrows$erow |"$'\n'
done
echo
echo "events inside the stages, seconds per step (-log_view; Output also holds the end-of-run fields and checkpoint):"
echo "| ranks | ${events// / | } |"
echo "|---|---|---|---|---|---|---|"
printf '%s' "$eventrows"
if [[ -n "${per_step[1]:-}" && -n "${per_step[2]:-}" ]]; then
  python3 -c "print('parallel efficiency 1 -> 2 ranks: %.0f %%' % (100 * ${per_step[1]} / (2 * ${per_step[2]})))"
fi
