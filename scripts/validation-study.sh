#!/usr/bin/env bash
# The validation study of docs/validation.md: the reconstructed Dragon Box at 256x256 on the
# rv32 model at 64 TMs, all eight configurations, with each modelling assumption switched
# from its sourced default (configs/lin2020.toml) to its alternative, one at a time.
#
#   scripts/validation-study.sh [OUT]       (default OUT: validation-study)
#
# Needs target/release/dualsplit (cargo build --release) and the shipped meshes
# (DUALSPLIT_SCENES, default ../shared/scenes; scripts/get-scenes.sh). Runs JOBS jobs at a
# time (default: the number of cores); every study shares one result cache, so an entry two
# studies have in common runs once. Rerunning skips what is done. Each study's table ends up
# in OUT/<study>/report/variants.md; docs/validation.md quotes them.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-validation-study}
S=${DUALSPLIT_SCENES:-../shared/scenes}
JOBS=${JOBS:-$(nproc)}
RES=${RES:-256}
D=target/release/dualsplit
mkdir -p "$OUT/scenes" "$OUT/cache"
BOX=$S/dragon_box.ply.gz
CLOSED=$OUT/scenes/dragon_box_closed.ply.gz
[ -f "$CLOSED" ] || $D -q scene dragon-box "$S/dragon.ply.gz" --closed -o "$CLOSED"

# study NAME [plan arguments...]: plan the study with the shared cache.
study() {
  local name=$1
  shift
  rm -rf "${OUT:?}/$name"
  $D -q plan --model rv32 --tms 64 --res "$RES" --out "$OUT/$name" "$@" >/dev/null
  rm -rf "${OUT:?}/$name/cache"
  ln -s ../cache "$OUT/$name/cache"
  echo "$name"
}

{
  study base "$BOX" --workload cast,path
  study l2-banking "$BOX" --workload path --vary l2.line_interleaved=false,true \
    --vary l2.refuse_conflicts=true,false
  study l2-latency "$BOX" --workload path --vary l2.hit_latency=5,3
  study dram-rows "$BOX" --workload path --vary dram.row_bytes=2048,8192
  study dram-faw "$BOX" --workload path --vary dram.t_faw=80,0
  study dram-refresh "$BOX" --workload path --vary dram.t_refi=15600,0
  study dram-queue "$BOX" --workload path --vary dram.read_queue=80,64
  study icache "$BOX" --workload path --vary units.icache_fetches=2,0
  study kernel-parity "$BOX" --workload cast,path --vary kernels.parity=true,false
  study instruction-form "$BOX" --workload cast,path --vary kernels.node_fetch=loads,operand
  study enclosure "$BOX" "$CLOSED" --workload path
  study previous-model "$BOX" --workload cast,path --config configs/model8.toml
} >"$OUT/studies.txt"

# Every entry of every study, run JOBS at a time (run-job skips entries already done).
while read -r name; do
  n=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['entries']))" \
    "$OUT/$name/plan.json")
  for ((i = 0; i < n; i++)); do echo "$OUT/$name $i"; done
done <"$OUT/studies.txt" | xargs -P "$JOBS" -n 2 $D -q run-job

while read -r name; do
  $D -q report --from "$OUT/$name" >/dev/null
  echo "== $name"
  cat "$OUT/$name/report/variants.md"
done <"$OUT/studies.txt"
