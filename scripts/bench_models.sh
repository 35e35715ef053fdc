#!/usr/bin/env bash
# Cost of each model at the paper's scene (input/bench/paper_scene.nml: 100^3 cells, phi = 0.4,
# ~764 spheres packed with gaps >= h_r, dt = 5e-4, 10 steps, 2 ranks): fluid only; + particles
# (no lubrication correction, no contacts); + full lubrication; + contacts (frictionless);
# + friction (mu_d = 0.5). Contacts come after lubrication: without it the explicit Hertz force
# at this step overlaps the spheres beyond the roughness and the run stops (as it should).
# Prints the wall time per step and the PETSc log stages per step. Results in doc/BENCHMARKS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
NP=${NP:-2}
mkdir -p build/bench
base=input/bench/paper_scene.nml
particles="&particles solid_fraction = 0.4, seed = 1, packing_sweeps = 50, packing_min_gap = 5e-3 /"
declare -a names=("fluid only" "+ particles" "+ full lubrication" "+ contacts" "+ friction")
declare -a extra=(
  "&lubrication model = 'none' /"
  "$particles
&lubrication model = 'none' /"
  "$particles
&lubrication model = 'full' /"
  "$particles
&lubrication model = 'full' /
&contact roughness = 5e-3 /"
  "$particles
&lubrication model = 'full' /
&contact roughness = 5e-3, friction = 0.5 /")
stage() { awk -v s="$1" '$2 == s":" {print $3; exit}' "$2"; }
printf '| models | s/step | Fluid | Particles | Contacts | Lubrication |\n|---|---|---|---|---|---|\n'
for k in "${!names[@]}"; do
  deck=build/bench/models_$k.nml
  { cat "$base"; printf '%s\n' "${extra[$k]}"; } > "$deck"
  log=build/bench/models_$k.log
  mpiexec --oversubscribe -n "$NP" "$BIN/fdsusp" "$deck" -log_view > "$log" 2>&1
  steps=$(awk '/^steps run:/ {print $3}' "$log")
  per=$(awk '/^steps run:/ {print $8}' "$log")
  row="| ${names[$k]} | $per"
  for s in Fluid Particles Contacts Lubrication; do
    t=$(stage "$s" "$log")
    row="$row | $(python3 -c "print('%.4f' % (${t:-0} / $steps))")"
  done
  echo "$row |"
done
