#!/usr/bin/env bash
# Regenerates the thumbnails docs/images/<scene>-<workload>.png: every shipped scene
# (../shared/scenes/*.ply.gz) and every builtin, in both workloads, with the scene's default
# camera and light, on BVH2 (every structure renders the same bits).
#
#   docs/images/make.sh                 # all scenes
#   RES=256 SPP=8 docs/images/make.sh bunny dragon_box builtin:cornell
#   WORKLOADS=path SPP=32 docs/images/make.sh dragon_sponza
#
# Thumbnails must stay small (<= 40 KB): path-traced noise compresses badly, so the path
# workload uses SPP samples (default 8), times 4 until the file fits (at most 128), while
# cast uses 1.
set -euo pipefail
cd "$(dirname "$0")/../.."
RES=${RES:-256}
SPP=${SPP:-8}
cargo build --release -q -p dualsplit
BIN=target/release/dualsplit
if [ $# -gt 0 ]; then
  SCENES=("$@")
else
  SCENES=()
  for f in ../shared/scenes/*.ply.gz; do SCENES+=("$(basename "$f" .ply.gz)"); done
  SCENES+=(builtin:cornell builtin:hairball builtin:forest builtin:atrium)
fi
for s in "${SCENES[@]}"; do
  case "$s" in
    builtin:*) spec="$s"; name="${s#builtin:}"; name="${name%%\?*}" ;;
    *) spec="../shared/scenes/$s.ply.gz"; name="$s" ;;
  esac
  for w in ${WORKLOADS:-cast path}; do
    spp=1
    [ "$w" = path ] && spp=$SPP
    out="docs/images/$name-$w.png"
    while :; do
      echo "== $out ($spp spp)"
      "$BIN" -q render "$spec" --accel bvh2 --workload "$w" --res "$RES" --spp "$spp" -o "$out"
      size=$(stat -c %s "$out")
      # Noise is what makes a thumbnail big: add samples until it fits.
      if [ "$size" -le 40960 ] || [ "$spp" -ge 128 ]; then break; fi
      echo "   $size bytes > 40 KB: more samples"
      spp=$((spp * 4))
    done
    if [ "$size" -gt 40960 ]; then echo "warning: $out is $size bytes (> 40 KB)" >&2; fi
  done
done
