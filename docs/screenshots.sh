#!/usr/bin/env bash
# Re-make the Rerun screenshots of docs/src/how-to/viewers.md ("Screenshots"):
#   docs/screenshots.sh [RERUN]     RERUN = the `rerun` binary (default: rerun on PATH)
# Runs the paper scene (the two-elbow run) and the unilateral one (its two-elbow run), converts
# both with `analyze view`, and lets Rerun draw each at 1440x900 and 1920x1080 logical points
# (`--window-size ... --screenshot-to`, the blueprint's first tab, the arm) into
# docs/src/images/rerun-*.png (Rerun draws them at twice the logical size), quantised with
# pngquant to keep the book small (about 120-150 KB each). CI does not run it.
# Needs: the `sim` and `analyze` binaries (built here with `cargo build --profile test --bins`,
# CARGO_TARGET_DIR honoured), Rerun 0.41 or later, Xvfb (`xvfb-run`) and a Vulkan driver (Mesa's
# software one, lavapipe, will do: `apt-get install xvfb mesa-vulkan-drivers`) and `pngquant`.
set -euo pipefail
cd "$(dirname "$0")/.."
rerun="${1:-rerun}"
target="$(realpath -m "${CARGO_TARGET_DIR:-target}")"
sim="$target/debug/sim"
analyze="$target/debug/analyze"
need() { command -v "$1" > /dev/null || { echo "screenshots.sh: needs $1 ($2)" >&2; exit 2; }; }
need "$rerun" "Rerun 0.41 or later: pip install rerun-sdk"
need xvfb-run "apt-get install xvfb"
need pngquant "apt-get install pngquant"
lvp=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
[ -e "$lvp" ] || { echo "screenshots.sh: needs a Vulkan driver (apt-get install mesa-vulkan-drivers)" >&2; exit 2; }
[ -x "$sim" ] && [ -x "$analyze" ] || cargo build --profile test --bins --quiet

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$sim" -q -o "$tmp" > /dev/null
"$analyze" view -q "$tmp/paper-two-elbow.mcap" -o "$tmp/two-elbow.rrd"
"$analyze" view -q "$tmp/paper-unilateral-two-elbow-unilateral.mcap" -o "$tmp/unilateral.rrd"
for run in two-elbow unilateral; do
  for size in 1440x900 1920x1080; do
    VK_ICD_FILENAMES="$lvp" xvfb-run -a -s "-screen 0 ${size}x24" \
      "$rerun" "$tmp/$run.rrd" --window-size "$size" --screenshot-to "$tmp/$run-$size.png" > "$tmp/$run-$size.log" 2>&1
    pngquant --force --quality 50-80 --output "docs/src/images/rerun-$run-$size.png" "$tmp/$run-$size.png"
  done
done
ls -l docs/src/images/rerun-*.png
