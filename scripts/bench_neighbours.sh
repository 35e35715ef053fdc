#!/usr/bin/env bash
# Neighbour-search (and contact-evaluation) cost versus N, for doc/BENCHMARKS.md §3.
#   bash scripts/bench_neighbours.sh
# Builds the optimised objects with make, compiles scripts/bench_neighbours.F90 against the pure
# modules (kinds, vector, lees_edwards, neighbours, packing_geometry, packing, contact) and prints
# a Markdown table and the fitted exponent of build time against N (1 = linear).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
make -s all >/dev/null
build=build/opt
fc=${FC:-gfortran}
exe=$build/bench_neighbours
"$fc" -O2 -I "$build" -o "$exe" scripts/bench_neighbours.F90 \
  "$build"/src/kernels/{kinds,vector,lees_edwards,neighbours,packing_geometry,packing,contact}.o
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(uname -n), $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$exe"
