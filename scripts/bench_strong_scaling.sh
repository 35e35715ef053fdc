#!/usr/bin/env bash
# Strong scaling of lubrication dynamics (issue 45 item 4): the physics of
# input/bench_lubrication_dynamics.nml (phi = 0.4, mu_d = 0.5, eps_r = 5e-3, pair cut-off 1a,
# Lees-Edwards cube) at N spheres (8000 by default), the same in-run packing (seed 1) on each rank
# count. For each rank count: the loop's wall time per step (the run log's "wall time per step"),
# the PETSc log stages per step (Particles, Lubrication, Contacts, Output) and the speed-up over
# the first rank count. Wall times need an idle machine: run nothing beside it.
#   RANKS="1 2" N=8000 STEPS=100 bash scripts/bench_strong_scaling.sh
#   BIN=/path/to/other/bin TAG=before bash scripts/bench_strong_scaling.sh   (before/after pairs)
# Results in doc/BENCHMARKS.md §18; the DNS's counterpart is scripts/bench_paper.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
RANKS=${RANKS:-1 2}
N=${N:-8000}
STEPS=${STEPS:-100}
DT=${DT:-2e-3}
TAG=${TAG:-strong}
OPTIONS=${OPTIONS:-}
PHI=0.4
W=build/bench/strong_scaling
mkdir -p "$W"
side=$(/usr/bin/python3 -c "import math; print('%.4f' % ((4 / 3 * math.pi * $N / $PHI) ** (1 / 3)))")
stage() { awk -v s="$1" '$2 == s":" {print $3; exit}' "$2"; }
printf '| ranks | spheres | s/step | Particles | Lubrication | Contacts | Output | speed-up |\n'
printf '|---|---|---|---|---|---|---|---|\n'
first=""
for np in $RANKS; do
  deck=$W/${TAG}_np$np.nml
  cat > "$deck" <<EOF
&domain box = $side, $side, $side, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = $DT, steps = $STEPS /
&output directory = '$W/${TAG}_np$np', progress_every = 100000, series_every = 10 /
&particles solid_fraction = $PHI, seed = 1 /
&contact roughness = 5e-3, friction = 0.5 /
&run title = 'lubrication dynamics strong scaling: N = $N' /
EOF
  rm -rf "$W/${TAG}_np$np"
  log=$W/${TAG}_np$np.log
  mpiexec --oversubscribe -n "$np" "$BIN/fdsusp" "$deck" -log_view $OPTIONS > "$log" 2>&1
  steps=$(awk '/^steps run:/ {print $3}' "$log")
  step=$(awk '/^steps run:/ {print $8}' "$log")
  spheres=$(grep -o '[0-9]* rigid spheres' "$log" | head -1 | awk '{print $1}')
  [ -z "$first" ] && first=$step
  row="| $np | $spheres | $step"
  for s in Particles Lubrication Contacts Output; do
    t=$(stage "$s" "$log")
    row="$row | $(/usr/bin/python3 -c "print('%.4f' % (${t:-0} / $steps))")"
  done
  echo "$row | $(/usr/bin/python3 -c "print('%.2f' % ($first / $step))") |"
done
