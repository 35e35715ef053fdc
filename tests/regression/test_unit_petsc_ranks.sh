#!/usr/bin/env bash
# The unit tests on PETSc (tests/unit_petsc/test_*.F90) on 3 ranks; tests/run_tests.sh runs each of
# them as a singleton too.
# Invariant: each program's checks hold whatever the number of ranks: its verdicts are of global
# quantities (test_fluid_solvers: 8 x 6 x 4 split 3 x 1 x 1 by PETSc, whose z-slabs for FFTW are
# 2, 2 and 0 planes, so the transforms scatter between layouts and one rank holds no slab; and
# 8 x 6 x 6 split 1 x 1 x 3, the pressure's Krylov solve on two-level cell-centred multigrid;
# test_checkpoint_roundtrip: the fields through PETSc's parallel HDF5 viewer; test_series_append:
# rank 0 alone writes the series, the others learn its verdicts; test_contacts_shares: every rank
# writes the springs of its share, each a run of the rows; test_sphere_halo also on 5 ranks,
# where a slab has ranks beyond reach). A run passes when it exits 0 and
# its output ends with the program's 'all N checks passed'. The tolerances are the programs' own.
# 3 ranks oversubscribe the 2 cores: ~5 s in all.
set -u
. "$(dirname "$0")/../checks.sh"     # check_result, checks_finish
root=${FDSUSP_ROOT:-$(cd "$(dirname "$0")/../.." && pwd)}
unit_dir=${FDSUSP_UNIT_DIR:-$root/build/opt/tests}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

run() {  # run PROGRAM [ARGS...]: on 3 ranks (NP=n: on n)
  local name=$1 prog=$unit_dir/$1 rc np=${NP:-3}; shift
  if [ ! -x "$prog" ]; then
    check_result 1 "$name $*: the program $prog is not built (make all)"
    return
  fi
  timeout 300 mpiexec -n "$np" --oversubscribe "$prog" "$@" > "$tmp/out" 2>&1; rc=$?
  sed 's/^/    | /' "$tmp/out"
  grep -q "^$name: all [0-9]* checks passed" "$tmp/out" && ! grep -q 'FAIL' "$tmp/out"
  check_result $(( rc == 0 && $? == 0 ? 0 : 1 )) "$name $* on $np ranks: exit $rc, $(grep -E "^$name: " "$tmp/out" | tail -1)"
}

for src in "$root"/tests/unit_petsc/test_*.F90; do
  run "$(basename "$src" .F90)"
done
run test_fluid_solvers -test_cells 8,6,6
# the halo with slabs beyond reach of one another (the all-to-all path of the first distribution)
NP=5 run test_sphere_halo
checks_finish
