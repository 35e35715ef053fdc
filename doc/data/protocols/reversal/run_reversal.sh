#!/bin/bash
# Run (or continue) the reversal decks one after another on one core, from the checkout:
#   nohup bash doc/data/protocols/reversal/run_reversal.sh NAME [NAME ...] &
# A run whose log says it finished at the deck's steps, or stopped by the overlap guard
# (failed_state.h5), is skipped; any other continues from its checkpoint (-continue), also one
# finished earlier whose deck now asks for more steps.
cd "$(dirname "$0")/../../../.." || exit 1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
dir=doc/data/protocols/reversal
for n in "$@"; do
  out=out/protocols/reversal/$n
  log=out/protocols/reversal/$n.log
  steps=$(sed -n 's/.*steps = \([0-9]*\).*/\1/p' $dir/$n.nml | head -1)
  if [ -f $log ] && grep -q "finished at step *$steps\$" $log; then continue; fi
  if [ -f $out/failed_state.h5 ]; then continue; fi
  mkdir -p out/protocols/reversal
  echo "== $n start $(date -u +%FT%TZ)" >> $log
  /usr/bin/time -f "== $n cpu user %U s sys %S s wall %e s" nice -n 10 bin/fdsusp $dir/$n.nml -continue >> $log 2>&1
  echo "== $n end $(date -u +%FT%TZ) status $?" >> $log
done
