#!/bin/sh
# Sweeps the RT unit's warps and MSHRs of configs/rtx2060.toml on one scene (the `simt`
# model): one `dualsplit simulate` per value, the other key at the RTX 2060's value, then a
# table of frame time, RT-unit occupancy and DRAM bytes per ray per structure.
#
#   scripts/simt-sweep.sh SCENE [WORKLOAD] [RES] [OUTDIR]
set -eu
scene=$1
workload=${2:-cast}
res=${3:-256}
out=${4:-simt-sweep}
bin=${DUALSPLIT:-target/release/dualsplit}
accels=bvh2,bvh8,cwbvh,dst,dst-q
mkdir -p "$out"
run() { # key value
    cfg="$out/$1-$2.toml"
    sed "s/^$1 = [0-9]*/$1 = $2/" configs/rtx2060.toml > "$cfg"
    "$bin" simulate "$scene" --model simt --config "$cfg" --accel "$accels" \
        --workload "$workload" --res "$res" --json="$out/$1-$2.json" > /dev/null
}
for w in 1 2 4 8 16; do run rt_max_warps "$w"; done
for m in 8 16 32 64 128 256; do run rt_max_mshr "$m"; done
python3 - "$out" <<'PY'
import glob, json, os, sys
print("| key | value | structure | frame ms | RT occupancy | DRAM B/ray | L1 hit rate |")
print("|---|---|---|---|---|---|---|")
def order(p):
    k, v = os.path.basename(p)[:-5].rsplit("-", 1)
    return (k, int(v))
for p in sorted(glob.glob(os.path.join(sys.argv[1], "*.json")), key=order):
    k, v = order(p)
    for r in json.load(open(p))["results"]:
        s = r["simt"]
        print(f"| {k} | {v} | {r['accel']} | {r['frame_ms']:.3f} | {s['rt_occupancy']:.2f} "
              f"| {s['dram_bytes_per_ray']:.0f} | {r['l1_hit_rate']:.3f} |")
PY
