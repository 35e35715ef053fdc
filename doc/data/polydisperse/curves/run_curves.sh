#!/bin/bash
# Run (or continue) the curves' decks one after another on one core, from the checkout:
#   nohup bash doc/data/polydisperse/curves/run_curves.sh [NAME ...] &
# Without names: every deck of queue.txt, in its order. A run already complete (summary.json
# "complete": true), stopped by the overlap guard (failed_state.h5) or refused (.refused) is
# skipped; one stopped by max_wall_hours continues from its checkpoint (-continue).
cd "$(dirname "$0")/../../../.." || exit 1
dir=doc/data/polydisperse/curves
names=("$@")
[ ${#names[@]} -eq 0 ] && read -r -a names < $dir/queue.txt
for n in "${names[@]}"; do
  out=out/polydisperse/curves/$n
  if [ -f $out/summary.json ] && grep -q '"complete": true' $out/summary.json; then continue; fi
  if [ -f $out/failed_state.h5 ] || [ -f out/polydisperse/curves/$n.refused ]; then continue; fi
  mkdir -p out/polydisperse/curves
  echo "== $n start $(date -u +%FT%TZ)" >> out/polydisperse/curves/$n.log
  nice -n 5 bin/fdsusp $dir/$n.nml -continue >> out/polydisperse/curves/$n.log 2>&1
  rc=$?
  echo "== $n end $(date -u +%FT%TZ) status $rc" >> out/polydisperse/curves/$n.log
  if [ $rc -ne 0 ] && [ ! -f $out/failed_state.h5 ]; then touch out/polydisperse/curves/$n.refused; fi
done
