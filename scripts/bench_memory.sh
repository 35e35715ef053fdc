#!/usr/bin/env bash
# Memory per grid cell (issue 45; doc/BENCHMARKS.md "Issue 45: memory per cell"): the fluid alone
# (input/bench/couette100.nml) and the paper's scene with its spheres (input/bench_paper.nml,
# ~764 spheres), on 1 and 2 ranks, a few steps each (memory does not grow after the first step).
# Memory per cell is the marginal cost of a cell: the peak resident set (VmHWM, summed over the
# ranks) of the deck at a/Delta = 5 (100^3 cells) minus that of the same deck at a/Delta = 4 (80^3
# cells, the same spheres), over the difference in cells; the libraries' and the spheres' fixed
# costs cancel. Beside it: the gross peak over the cells, and PETSc's own peak (PetscMalloc,
# summed over ranks) over the cells. Memory is not affected by a shared machine; the times are.
#   bash scripts/bench_memory.sh                 both decks, 1 and 2 ranks
#   RANKS=2 STEPS=2 bash scripts/bench_memory.sh
#   BIN=/path/to/other/bin bash scripts/bench_memory.sh   (before/after comparisons)
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
RANKS=${RANKS:-"1 2"}
STEPS=${STEPS:-3}
OPTIONS=${OPTIONS:-}
mkdir -p build/bench
# peak resident bytes summed over ranks: the run's own memory line, or -memory_view's (older binaries)
peak() {
  local mib
  mib=$(awk '/^memory: peak resident/ {for (i = 1; i <= NF; i++) if ($i == "ranks") {print $(i + 1); exit}}' "$1")
  if [[ -n "$mib" ]]; then python3 -c "print($mib * 1048576)"; return; fi
  awk '/^Maximum \(over computational time\) process memory/ {print $(NF-4); exit}' "$1"
}
malloc_peak() { awk '/^Maximum \(over computational time\) space PetscMalloc/ {print $(NF-4); exit}' "$1"; }
run() {   # deck cells_per_radius np tag -> log path
  local deck=build/bench/memory_$4.nml log=build/bench/memory_$4.log
  sed -e "s|directory = '[^']*'|directory = 'build/bench/memory_$4'|" -e "s|steps = [0-9]*|steps = $STEPS|" \
      -e "s|cells_per_radius = [0-9.]*|cells_per_radius = $2|" "$1" > "$deck"
  # -malloc_view: PETSc's peak (its allocation headers add well under 1 B per cell)
  mpiexec --oversubscribe -n "$3" "$BIN/fdsusp" "$deck" -memory_view -malloc_view $OPTIONS > "$log" 2>&1
  echo "$log"
}
printf '| case | ranks | B/cell (marginal, 100^3 - 80^3) | B/cell (gross, 100^3) | PetscMalloc B/cell (100^3) | peak resident 100^3 / 80^3, MB | s/step (100^3) |\n'
printf '|---|---|---|---|---|---|---|\n'
for case in fluid paper; do
  deck=input/bench/couette100.nml
  [[ $case == paper ]] && deck=input/bench_paper.nml
  for np in $RANKS; do
    big=$(run "$deck" 5 "$np" "${case}_5_np$np")
    small=$(run "$deck" 4 "$np" "${case}_4_np$np")
    pb=$(peak "$big"); ps=$(peak "$small"); mb=$(malloc_peak "$big")
    step=$(awk '/^steps run:/ {print $8}' "$big")
    python3 -c "
pb, ps, mb = $pb, $ps, ${mb:-0}
print('| %s | %d | %.0f | %.0f | %.0f | %.0f / %.0f | %s |' % ('$case', $np, (pb - ps) / (100**3 - 80**3), pb / 100**3,
      mb / 100**3, pb / 1e6, ps / 1e6, '$step'))"
  done
done
