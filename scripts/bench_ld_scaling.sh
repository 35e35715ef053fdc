#!/usr/bin/env bash
# The cost of lubrication dynamics (&fluid model = 'none', issue 30) against the number of spheres:
# the physics of input/bench_lubrication_dynamics.nml (phi = 0.4, mu_d = 0.5, eps_r = 5e-3, pair
# cut-off 1a, Lees-Edwards cube) at N = 500 ... 8000, one rank. For each N: CPU seconds of a run of
# STEPS steps minus those of the same deck with 0 steps (packing, set-up, output), per step and per
# strain; the CG iterations of the 6N solve over the second half of the run (the suspension has
# sheared into closer gaps by then) from -particles_ksp_converged_reason; the lubricating pairs.
# CPU time (the run's own, from /usr/bin/time) does not depend on what else the machine runs.
#   NS="500 1000 2000 4000 8000" STEPS=250 DT=2e-3 BIN=bin bash scripts/bench_ld_scaling.sh
# Results in doc/BENCHMARKS.md §11.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
NS=${NS:-500 1000 2000 4000 8000}
STEPS=${STEPS:-250}
DT=${DT:-2e-3}
PHI=0.4
W=build/bench/ld_scaling
mkdir -p "$W"

deck() {   # deck N STEPS: the bench deck's physics in a cube holding N spheres at PHI
  local side
  side=$(/usr/bin/python3 -c "import math; print('%.4f' % ((4 / 3 * math.pi * $1 / $PHI) ** (1 / 3)))")
  cat <<EOF
&domain box = $side, $side, $side, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = $DT, steps = $2 /
&output directory = '$W/out_$1_$2', progress_every = 100000, series_every = 10 /
&particles solid_fraction = $PHI, seed = 1 /
&contact roughness = 5e-3, friction = 0.5 /
&run title = 'lubrication dynamics scaling: N = $1' /
EOF
}

cpu() {    # cpu DECK LOG: user + system CPU seconds of one run
  rm -rf "$(awk -F"'" '/directory/ {print $2}' "$1")"
  /usr/bin/time -f '%U %S' -o "$2.time" "$BIN/fdsusp" "$1" -particles_ksp_converged_reason > "$2" 2>&1
  awk '{print $1 + $2}' "$2.time"
}

printf '%-6s %-8s %-10s %-12s %-14s %-16s %-10s\n' N spheres pairs 'CPU ms/step' 'CPU s/strain' \
  'CG its (2nd half)' 'strains/h'
for n in $NS; do
  deck "$n" 0 > "$W/deck_${n}_0.nml"
  deck "$n" "$STEPS" > "$W/deck_${n}.nml"
  c0=$(cpu "$W/deck_${n}_0.nml" "$W/log_${n}_0")
  c1=$(cpu "$W/deck_${n}.nml" "$W/log_${n}")
  /usr/bin/python3 - "$n" "$c0" "$c1" "$W/log_${n}" "$W/out_${n}_${STEPS}/series.h5" "$STEPS" "$DT" <<'EOF'
import re, sys, h5py
n, c0, c1, log, series, steps, dt = sys.argv[1:]
steps, dt = int(steps), float(dt)
text = open(log).read()
spheres = int(re.search(r'(\d+) rigid spheres', text).group(1))
its = [int(i) for i in re.findall(r'Linear particles_ solve converged due to \w+ iterations (\d+)', text)]
half = its[len(its) // 2:]
pairs = h5py.File(series)['lubrication_pairs'][()]
per_step = (float(c1) - float(c0)) / steps
print('%-6s %-8d %-10d %-12.1f %-14.1f %-16s %-10.0f' % (
    n, spheres, int(pairs[len(pairs) // 2:].mean()), 1e3 * per_step, per_step / dt,
    '%.0f (%d-%d)' % (sum(half) / len(half), min(half), max(half)) if half else '-',
    3600 * dt / per_step))
EOF
done

# The bench deck itself (input/bench_lubrication_dynamics.nml: its packing in-run, its steps):
# strains per hour of CPU on one core, against the issue's target of 40.
if [[ -z "${NS_ONLY:-}" ]]; then
  deck=input/bench_lubrication_dynamics.nml
  sed 's/^ *steps *=.*/  steps = 0/' "$deck" > "$W/bench_0.nml"
  c0=$(cpu "$W/bench_0.nml" "$W/log_bench_0")
  c1=$(cpu "$deck" "$W/log_bench")
  /usr/bin/python3 - "$c0" "$c1" "$deck" <<'PY'
import re, sys
c0, c1, deck = float(sys.argv[1]), float(sys.argv[2]), open(sys.argv[3]).read()
steps = int(re.search(r'^\s*steps\s*=\s*(\d+)', deck, re.M).group(1))
dt = float(re.search(r'^\s*dt\s*=\s*([0-9.eE+-]+)', deck, re.M).group(1))
print('bench deck %s: %d steps of dt %g, %.1f CPU ms/step, %.1f CPU s/strain, %.0f strains per hour '
      'on one core (target 40); set-up %.1f CPU s' % (sys.argv[3], steps, dt, 1e3 * (c1 - c0) / steps,
                                                      (c1 - c0) / (steps * dt), 3600 * steps * dt / (c1 - c0), c0))
PY
fi
