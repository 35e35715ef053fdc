#!/usr/bin/env bash
# The implicit 6N particle system with lubrication at ~1000 spheres (phi = 0.4, Couette cell at shear rate 1): the default
# (CG + point-block Jacobi) against sparse Cholesky factorisations: CHOLMOD, which orders with
# METIS (its nested dissection; Debian's MUMPS is built without METIS and falls back to AMD), and
# MUMPS.
# One rank; mean time of one assembly + solve as fdsusp reports it. Called by scripts/bench.sh;
# results in doc/BENCHMARKS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
mkdir -p build/bench
"$BIN/fdsusp-pack" input/bench/pack1000.nml > build/bench/pack1000.log 2>&1
run() {
  local name=$1; shift
  local log=build/bench/solver1000_$name.log
  mpiexec --oversubscribe -n 1 "$BIN/fdsusp" input/bench/solver1000.nml "$@" > "$log" 2>&1
  local n=$(awk '/rigid spheres/ {for (i = 1; i <= NF; i++) if ($i == "rigid") print $(i-1); exit}' "$log")
  local pairs=$(/usr/bin/python3 -c "import h5py; print(int(h5py.File('build/bench/solver1000/series.h5')['lubrication_pairs'][-1]))")
  printf 'solver1000  %-28s spheres %s  lubricating pairs %s  %s\n' "$name" "$n" "$pairs" \
    "$(grep -o 'sparse solves, mean *[0-9.]* ms' "$log")"
}
run cg-pbjacobi
# the factorisations need an AIJ matrix (PETSc's CHOLMOD takes aij, or sbaij of block size 1)
run cholesky-cholmod-metis -particles_mat_type aij -particles_ksp_type preonly -particles_pc_type cholesky \
    -particles_pc_factor_mat_solver_type cholmod
run cholesky-mumps-amd -particles_mat_type aij -particles_ksp_type preonly -particles_pc_type cholesky \
    -particles_pc_factor_mat_solver_type mumps
