#!/usr/bin/env bash
# The validation study of docs/validation.md: the paper's Dragon Box as SimTRaX ships it
# (docs/scenes.md) at 256x256 on the rv32 model at 64 TMs, all eight configurations, with
# each modelling assumption switched from its sourced default (configs/lin2020.toml) to its
# alternative, one at a time.
#
#   scripts/validation-study.sh [OUT]       (default OUT: validation-study)
#
# Needs target/release/dualsplit (cargo build --release) and the Stanford dragon
# (DUALSPLIT_SCENES, default ../shared/scenes; scripts/get-scenes.sh): the script makes
# SimTRaX's Dragon Box and the reconstruction from it into OUT/scenes. RES (default 256) is
# the studies' frame size; the paper-frame study runs at 1024x1024, the path-512 and
# path-1024 studies path-trace at 512x512 and 1024x1024 (SKIP_PAPER_FRAME=1 leaves all three
# out: hours of one core). Runs JOBS jobs at a
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
# The paper's eight configurations (the structures beyond the paper are not studied here).
PAPER=bvh2,bvh2+,bvh4,bvh4+,bvh8,bvh8+,dst-sw,dst
mkdir -p "$OUT/scenes" "$OUT/cache"
BOX=$OUT/scenes/dragon_box.ply.gz
RECON=$OUT/scenes/dragon_box_recon.ply.gz
CLOSED=$OUT/scenes/dragon_box_recon_closed.ply.gz
[ -f "$BOX" ] || $D -q scene dragon-box "$S/dragon.ply.gz" -o "$BOX"
[ -f "$RECON" ] || $D -q scene dragon-box "$S/dragon.ply.gz" --reconstruction -o "$RECON"
[ -f "$CLOSED" ] || $D -q scene dragon-box "$S/dragon.ply.gz" --reconstruction --closed \
  -o "$CLOSED"

# study NAME RES [plan arguments...]: plan the study at RES x RES with the shared cache.
study() {
  local name=$1 res=$2
  shift 2
  rm -rf "${OUT:?}/$name"
  $D -q plan --model rv32 --tms 64 --res "$res" --accel "$PAPER" --out "$OUT/$name" "$@" \
    >/dev/null
  rm -rf "${OUT:?}/$name/cache"
  ln -s ../cache "$OUT/$name/cache"
  echo "$name"
}

{
  study base "$RES" "$BOX" --workload cast,path
  # The paper's frame size for its ray casting (Table 4 states 1024x1024), both workloads,
  # and path tracing at 512x512 and 1024x1024 (the paper states no size for Table 5).
  if [ -z "${SKIP_PAPER_FRAME:-}" ]; then
    study paper-frame 1024 "$BOX" --workload cast,path
    study path-512 512 "$BOX" --workload path
    study path-1024 1024 "$BOX" --workload path
  fi
  study l2-banking "$RES" "$BOX" --workload path --vary l2.line_interleaved=false,true \
    --vary l2.refuse_conflicts=true,false
  study l2-latency "$RES" "$BOX" --workload path --vary l2.hit_latency=5,3
  study dram-rows "$RES" "$BOX" --workload path --vary dram.row_bytes=8192,2048
  study dram-faw "$RES" "$BOX" --workload path --vary dram.t_faw=80,0
  study dram-refresh "$RES" "$BOX" --workload path --vary dram.t_refi=15600,0
  study dram-refresh-burst "$RES" "$BOX" --workload path --vary dram.refresh_burst=8,1
  study dram-queue "$RES" "$BOX" --workload path --vary dram.read_queue=80,64
  study dram-keep-open "$RES" "$BOX" --workload path --vary dram.keep_open=true,false
  study dram-writes "$RES" "$BOX" --workload path --vary dram.write_queue=80,0
  study icache "$RES" "$BOX" --workload path --vary units.icache_fetches=2,0
  # Functional units shared per TM as SimTRaX's configs have them (the paper: per TP).
  study fu-shared-65nm "$RES" "$BOX" --workload cast,path --config configs/fu-shared-65nm.toml
  study fu-shared-bigcache "$RES" "$BOX" --workload cast,path \
    --config configs/fu-shared-bigcache.toml
  # Shadow rays at every hit, or none (the paper does not say).
  study shadows "$RES" "$BOX" --workload path --vary kernels.shadows=true,false
  study kernel-parity "$RES" "$BOX" --workload cast,path --vary kernels.parity=true,false
  study instruction-form "$RES" "$BOX" --workload cast,path --vary kernels.node_fetch=loads,operand
  # The scene: SimTRaX's Dragon Box against the reconstruction, open and closed.
  study enclosure "$RES" "$BOX" "$RECON" "$CLOSED" --workload path
  study previous-model "$RES" "$BOX" --workload cast,path --config configs/model8.toml
  # More TMs: the paper's Table 7 goes to 128.
  study tms-128 "$RES" "$BOX" --workload path --vary tms=128
  # A mesh the model was not developed on: the Dragon Sponza stand-in (the Stanford dragon in
  # the Dabrovic Sponza atrium), lin2020 and model 8.
  study holdout "$RES" "$S/dragon_sponza.ply.gz" --workload path
  study holdout-previous "$RES" "$S/dragon_sponza.ply.gz" --workload path \
    --config configs/model8.toml
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
