#!/usr/bin/env bash
# How dense the packer gets, for doc/VALIDATION.md "Packings": builds scripts/pack_reach.F90
# against a copy of the packing kernels whose phi_max is lifted to 0.64 (so that targets past the
# shipped limit run and show where the compression jams), and prints a Markdown table.
#   bash scripts/pack_reach.sh [N [SEEDS [PHI ...]]]   (defaults 1000, 3, 0.55 ... 0.63; the jams
#   above 0.61 take minutes each)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
make -s all >/dev/null
build=build/opt
fc=${FC:-gfortran}
work=$build/pack_reach
mkdir -p "$work"
sed 's/phi_max = [0-9.]*_dp/phi_max = 0.64_dp/' src/kernels/packing_geometry.F90 > "$work/packing_geometry.F90"
cp src/kernels/packing.F90 "$work/packing.F90"
for m in packing_geometry packing; do
  "$fc" -O2 -cpp -I "$build" -J "$work" -c "$work/$m.F90" -o "$work/$m.o"
done
"$fc" -O2 -I "$work" -I "$build" -o "$work/pack_reach" scripts/pack_reach.F90 \
  "$work"/packing_geometry.o "$work"/packing.o "$build"/src/kernels/{kinds,vector,columns,lees_edwards,neighbours}.o
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(uname -n), $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
GFORTRAN_UNBUFFERED_PRECONNECTED=y "$work/pack_reach" "$@"
