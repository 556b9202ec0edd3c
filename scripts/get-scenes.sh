#!/usr/bin/env bash
# Downloads the public originals of the shipped scene meshes from their canonical addresses,
# checks them by SHA-256, and converts them into the scenes folder (docs/scenes.md, "The
# shipped meshes"): shared/scenes beside the checkout, or the folder given as the first
# argument, or $DUALSPLIT_SCENES.
#
#   scripts/get-scenes.sh [DIR]
#
# Needs curl, tar, unzip (or python3) and the dualsplit binary ($DUALSPLIT_BIN, else
# target/release/dualsplit, built with cargo when missing). Downloads are kept in
# DIR/downloads and reused when their checksum matches.
#
# Three kinds of check (docs/scenes.md says which were verified offline):
#   archive   SHA-256 of the downloaded file
#   member    SHA-256 of the PLY taken out of an archive
#   triangles the triangles' SHA-256 that `dualsplit scene` prints (36-byte records of
#             little-endian f32 in file order), which must equal the shipped file's
# A check whose value is unknown prints the value found instead. A failed check stops the
# script, except the triangle checks marked `soft` (conversions not reproduced offline),
# which warn.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-${DUALSPLIT_SCENES:-$root/../shared/scenes}}"
mkdir -p "$out/downloads"
out="$(cd "$out" && pwd)"
dl="$out/downloads"

bin="${DUALSPLIT_BIN:-$root/target/release/dualsplit}"
if [ ! -x "$bin" ]; then
  echo "== building the dualsplit binary"
  (cd "$root" && cargo build --release -q -p dualsplit)
fi

sha() { sha256sum "$1" | cut -d' ' -f1; }

# check FILE WANT WHAT: WANT is a SHA-256 or "unknown".
check() {
  local got
  got="$(sha "$1")"
  if [ "$2" = unknown ]; then
    echo "   $3 $(basename "$1"): sha256 $got (no recorded value to compare with)"
  elif [ "$got" != "$2" ]; then
    echo "error: $3 $1 has sha256 $got, expected $2" >&2
    exit 1
  else
    echo "   $3 $(basename "$1"): sha256 ok"
  fi
}

# fetch URL FILE WANT: downloads URL into DIR/downloads/FILE unless a copy with the
# recorded checksum is there, then checks it.
fetch() {
  local file="$dl/$2"
  if [ -f "$file" ] && [ "$3" != unknown ] && [ "$(sha "$file")" = "$3" ]; then
    echo "   $2: already downloaded"
  else
    echo "   downloading $1"
    curl -fL --retry 3 -o "$file.part" "$1"
    mv "$file.part" "$file"
  fi
  check "$file" "$3" archive
}

unzip_to() {
  if command -v unzip >/dev/null 2>&1; then
    unzip -q -o "$1" -d "$2"
  else
    python3 -m zipfile -e "$1" "$2"
  fi
}

# triangles OUTPUT-LINE WANT NAME [soft]: compares the printed triangle checksum.
triangles() {
  local got
  got="$(printf '%s\n' "$1" | sed -n 's/.*triangles sha256 \([0-9a-f]*\).*/\1/p')"
  if [ "$got" = "$2" ]; then
    echo "   $3: triangles sha256 ok (the shipped file's triangles)"
  elif [ "${4:-}" = soft ]; then
    echo "warning: $3: triangles sha256 $got differs from the shipped file's $2" >&2
  else
    echo "error: $3: triangles sha256 $got, expected $2 (the shipped file's)" >&2
    exit 1
  fi
}

# convert INPUT NAME WANT [soft]: INPUT → DIR/NAME.ply.gz.
convert() {
  local line
  line="$("$bin" -q scene convert "$1" -o "$out/$2.ply.gz")"
  echo "   $line"
  triangles "$line" "$3" "$2.ply.gz" "${4:-}"
}

echo "== Stanford dragon (vrip reconstruction and its decimations) and the Dragon Box"
fetch https://graphics.stanford.edu/pub/3Dscanrep/dragon/dragon_recon.tar.gz dragon_recon.tar.gz \
  74ac1d90989c9b1732edee82d57e9ce71452144cf4355f108d8c9c616d28d02f
tar -xzf "$dl/dragon_recon.tar.gz" -C "$dl"
check "$dl/dragon_recon/dragon_vrip.ply" fea87ff48f2aba22fb53e7b67c3ff3f7b8c2a3b3a0653af62c48bba67c6d5744 member
check "$dl/dragon_recon/dragon_vrip_res2.ply" f64cd2d043551ec82643d9987d1d26d35018238d501b346481e3b89d6e224da4 member
check "$dl/dragon_recon/dragon_vrip_res3.ply" f32b87762894bde78cd45dc05aa9fde0f5ad390c944168a96e97191ff1fc6d45 member
check "$dl/dragon_recon/dragon_vrip_res4.ply" 23fe8c7b3b006de91d5307504c4a1624e5e5e4d4fcb9e96569b00ce971fdc480 member
convert "$dl/dragon_recon/dragon_vrip.ply" dragon a3cd6780c8d6e7edaf38c30ffd098aa54354c054f33d966db13f9e2478b4bc07
convert "$dl/dragon_recon/dragon_vrip_res2.ply" dragon_res2 e39c261ed5e4c833ed3bfd3f64b19ca1d97d154eaaa1c5a95293d89c9f1ceec5
convert "$dl/dragon_recon/dragon_vrip_res3.ply" dragon_res3 669aab76ea14fdede3e0183abc00dc5c232709b93fea3f01781f356b57e0d479
convert "$dl/dragon_recon/dragon_vrip_res4.ply" dragon_res4 7267941007a6a4f987cd338e87b7d437b12288356379f5bf7f165e41510a6466
# The paper's Dragon Box as SimTRaX ships it (docs/scenes.md), and this project's earlier
# reconstruction of it.
line="$("$bin" -q scene dragon-box "$out/dragon.ply.gz" -o "$out/dragon_box.ply.gz")"
echo "   $line"
triangles "$line" e41ecebedc34fa020bc87a27761f3ca62bb299995051a8931d2d379835cf047f dragon_box.ply.gz
line="$("$bin" -q scene dragon-box --reconstruction "$out/dragon.ply.gz" \
  -o "$out/dragon_box_recon.ply.gz")"
echo "   $line"
triangles "$line" 66f9b6ae1b0bcd2576f205d4ffcb9a08ef5edd9fc520f4db84c21248308f8019 dragon_box_recon.ply.gz

echo "== Stanford bunny (bun_zipper)"
fetch https://graphics.stanford.edu/pub/3Dscanrep/bunny.tar.gz bunny.tar.gz \
  a5720bd96d158df403d153381b8411a727a1d73cff2f33dc9b212d6f75455b84
tar -xzf "$dl/bunny.tar.gz" -C "$dl" bunny/reconstruction/bun_zipper.ply
check "$dl/bunny/reconstruction/bun_zipper.ply" unknown member
convert "$dl/bunny/reconstruction/bun_zipper.ply" bunny a6f915eba5c4ad860c16ddeee9729a696236eaee2939fda44cba826189fca0f8 soft

echo "== Marko Dabrovic's Sponza atrium (the 2002 model)"
fetch https://casual-effects.com/g3d/data10/research/model/dabrovic_sponza/sponza.zip dabrovic_sponza.zip unknown
rm -rf "$dl/dabrovic_sponza"
unzip_to "$dl/dabrovic_sponza.zip" "$dl/dabrovic_sponza"
obj="$(find "$dl/dabrovic_sponza" -iname 'sponza.obj' | head -n 1)"
[ -n "$obj" ] || { echo "error: no sponza.obj in $dl/dabrovic_sponza.zip" >&2; exit 1; }
check "$obj" unknown member
convert "$obj" sponza_dabrovic 2ab8c6549abe12655808d935bb59866e615bab7c379ea9dbaade6395a669d9ab soft

echo "== Crytek Sponza (Frank Meinl's 2010 update, CC BY 3.0), glTF from the Khronos glTF sample models"
base=https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/main/2.0/Sponza/glTF
fetch "$base/Sponza.gltf" Sponza.gltf unknown
fetch "$base/Sponza.bin" Sponza.bin unknown
# Geometry only: the loader reads positions, indices and node transforms, never textures.
cp "$dl/Sponza.gltf" "$out/crytek_sponza.gltf"
cp "$dl/Sponza.bin" "$out/Sponza.bin"
"$bin" info "$out/crytek_sponza.gltf"

echo "== done: $out"
echo "   not made here: dragon_sponza.ply.gz (docs/scenes.md says how it was composed)"
