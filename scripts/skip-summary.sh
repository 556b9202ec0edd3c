#!/usr/bin/env bash
# The summary line of the scene skips in a saved `cargo test` log: testkit writes
# `skipped scene: NAME not found in DIRS` to standard error each time a test finds no mesh
# NAME (crates/testkit/src/scenes.rs). Prints `skipped scenes: none`, or the number of skips
# and each missing mesh with its count.
#
#   scripts/skip-summary.sh LOG
set -euo pipefail
log="${1:?usage: scripts/skip-summary.sh LOG}"
# `cargo test -q` prints a dot per test without a newline, so a skip may start mid-line.
lines="$(grep -ao 'skipped scene: .*' "$log" || true)"
if [ -z "$lines" ]; then
  echo "skipped scenes: none"
  exit 0
fi
n="$(printf '%s\n' "$lines" | wc -l)"
meshes="$(printf '%s\n' "$lines" | sed -E 's/^skipped scene: (.*) not found in .*/\1/' | sort | uniq -c \
  | awk '{ printf "%s%s ×%d", sep, $2, $1; sep = ", " }')"
echo "skipped scenes: $n skips for missing meshes: $meshes"
