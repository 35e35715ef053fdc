#!/usr/bin/env bash
# Weak scaling by oversubscription (issue 45 item 4): 1 to 8 ranks at fixed spheres (and, in the
# DNS, fixed cells) per rank, in both models; for each rank count the peak memory of a rank (the
# largest over ranks, PETSc's -memory_view) and the bytes each rank sends per step, counted by Open
# MPI's monitoring components (pml and coll "monitoring": every point-to-point message, and the
# point-to-point traffic that collectives make inside the library), as the difference of a run of
# STEPS_LONG and one of STEPS_SHORT steps, so that set-up, packing and output drop out. Times are
# not measured: the ranks share this machine's cores. Weak scaling is flat when both columns stay
# flat (bytes against 2 ranks: one rank sends none); a column that grows like the rank count shows state or traffic that grows with the total.
#   bash scripts/bench_weak_scaling.sh                              (ld and dns, 1 2 4 8 ranks)
#   MODELS=ld RANKS="1 2" PER_RANK=500 bash scripts/bench_weak_scaling.sh
#   OPTIONS="-ld_local_set 0" MODELS=ld bash scripts/bench_weak_scaling.sh   (options for every run)
#   SERIES_EVERY=1 MODELS=ld bash scripts/bench_weak_scaling.sh   (a series record every step, the
#        default cadence; otherwise none in the runs, so that only the step's traffic is counted)
# Decks (z is the direction the grid is split in, so each rank's share is a slab of the same size):
#   ld:  lubrication dynamics, the bench deck's physics (phi 0.4, mu_d 0.5, eps_r 5e-3, Lees-Edwards),
#        PER_RANK spheres per rank (default 500) in a box L x L x (NP L);
#   dns: the Couette cell 8a x 20a x (8a NP) at a/Delta 4 (81920 cells per rank), phi 0.3 (~92 spheres
#        per rank), mu_d 0.5, full lubrication, dt 1e-3.
# Results: doc/SCALING.md.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
BIN=${BIN:-bin}
MODELS=${MODELS:-"ld dns"}
RANKS=${RANKS:-"1 2 4 8"}
PER_RANK=${PER_RANK:-500}
OPTIONS=${OPTIONS:-}
SERIES_EVERY=${SERIES_EVERY:-100000}
STEPS_SHORT=${STEPS_SHORT:-2}
STEPS_LONG=${STEPS_LONG:-6}
W=build/bench/weak_scaling
mkdir -p "$W"
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3

deck() {   # deck MODEL NP STEPS
  local model=$1 np=$2 steps=$3 out=$W/out_$1_$2_$3
  if [[ $model == ld ]]; then
    local side
    side=$($PY -c "import math; print('%.4f' % ((4 / 3 * math.pi * $PER_RANK / 0.4) ** (1 / 3)))")
    cat <<EOF
&domain box = $side, $side, $($PY -c "print('%.4f' % ($side * $np))"), y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = $steps /
&output directory = '$out', progress_every = 100000, series_every = $SERIES_EVERY, checkpoint_every = 0 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5e-3, friction = 0.5 /
&run title = 'weak scaling, lubrication dynamics, $np ranks' /
EOF
  else
    cat <<EOF
&domain box = 8, 20, $((8 * np)), cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-3, steps = $steps /
&output directory = '$out', progress_every = 100000, series_every = $SERIES_EVERY, checkpoint_every = 0 /
&particles solid_fraction = 0.3, seed = 1 /
&contact roughness = 5e-3, friction = 0.5 /
&lubrication model = 'full' /
&run title = 'weak scaling, DNS, $np ranks' /
EOF
  fi
}

# run MODEL NP STEPS: prints "spheres peak_memory_max_per_rank bytes_sent and its point-to-point and
# collective parts", the bytes those of the rank that sent most
run() {
  local model=$1 np=$2 steps=$3 tag=$W/$1_$2_$3
  deck "$model" "$np" "$steps" > "$tag.nml"
  rm -rf "$W/out_${model}_${np}_${steps}" "$tag".prof*
  mpiexec --oversubscribe -n "$np" --mca pml_monitoring_enable 2 --mca pml_monitoring_enable_output 3 \
      --mca pml_monitoring_filename "$tag.prof" "$BIN/fdsusp" "$tag.nml" -memory_view $OPTIONS > "$tag.log" 2>&1
  local spheres mem
  spheres=$(awk '/^packing:/ {print $2; exit}' "$tag.log")
  mem=$(awk '/^Maximum .*process memory/ {print $(NF-2); exit}' "$tag.log")
  # the monitoring files: one per rank, a line "E|I  from  to  N bytes  M msgs sent ..." per peer
  "$PY" - "$tag.prof" "$np" "${spheres:-0}" "$mem" <<'EOF'
import glob, sys
stem, np_, spheres, mem = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
# E: the program's and PETSc's point-to-point messages (ghost exchanges, matrix products); I: those
# the library makes inside collectives (reductions, gathers, FFTW's transposes)
sent = {k: [0] * np_ for k in 'EI'}
for f in glob.glob(stem + '.*.prof'):
    for line in open(f):
        w = line.split()
        if len(w) > 4 and w[0] in sent and w[4] == 'bytes':
            sent[w[0]][int(w[1])] += int(w[3])
total = [e + i for e, i in zip(sent['E'], sent['I'])]
rank = max(range(np_), key=lambda r: total[r])
print(spheres, mem, total[rank], sent['E'][rank], sent['I'][rank])
EOF
}

echo "# weak scaling on $(hostname), $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ), commit $(git rev-parse --short HEAD 2>/dev/null || echo none); steps $STEPS_SHORT and $STEPS_LONG"
printf '%-4s %5s %8s %10s %13s %10s %18s %12s %14s %14s\n' model ranks spheres cells/rank "peak MB/rank" "vs 1 rank" "sent B/rank/step" "vs 2 ranks" "point-to-point" "collectives"
for model in $MODELS; do
  mem1=''; sent1=''
  for np in $RANKS; do
    read -r spheres mem_a sent_a e_a i_a < <(run "$model" "$np" "$STEPS_SHORT")
    read -r _ mem_b sent_b e_b i_b < <(run "$model" "$np" "$STEPS_LONG")
    per_step=$("$PY" -c "print(($sent_b - $sent_a) / ($STEPS_LONG - $STEPS_SHORT))")
    e_step=$("$PY" -c "print(($e_b - $e_a) / ($STEPS_LONG - $STEPS_SHORT))")
    i_step=$("$PY" -c "print(($i_b - $i_a) / ($STEPS_LONG - $STEPS_SHORT))")
    mem_mb=$("$PY" -c "print('%.1f' % (max($mem_a, $mem_b) / 1e6))")
    # the references: one rank's memory; the first rank count that sends anything (one rank sends nothing)
    [[ -z $mem1 ]] && mem1=$mem_mb
    [[ -z $sent1 && $np -gt 1 ]] && sent1=$per_step
    cells=0; [[ $model == dns ]] && cells=81920
    printf '%-4s %5d %8s %10d %13s %10s %18.0f %12s %14.0f %14.0f\n' "$model" "$np" "$spheres" "$cells" "$mem_mb" \
        "$("$PY" -c "print('%.2f' % ($mem_mb / $mem1))")" "$per_step" \
        "$("$PY" -c "print('%.2f' % ($per_step / ${sent1:-0}) if ${sent1:-0} > 0 else '-')")" "$e_step" "$i_step"
  done
done
