#!/usr/bin/env bash
# Re-make the Rerun screenshots of docs/src/how-to/viewers.md ("Screenshots"):
#   docs/screenshots.sh [RERUN]     RERUN = the `rerun` binary (default: rerun on PATH)
# Runs the paper scene (the two-elbow run), the unilateral one (its two-elbow run) and the
# contact-shapes demo (docs/src/how-to/contact-shapes: a sphere pad, a capsule and a cylinder's
# rims), converts each with `analyze view` (`--tab` chooses the tab the file opens on, the only
# tab `--screenshot-to` pictures) and lets Rerun draw each at 1440x900 and 1920x1080 logical
# points (`--window-size ... --screenshot-to`) into docs/src/images/rerun-*.png (Rerun draws
# them at twice the logical size), quantised with pngquant to keep the book small (about
# 100-150 KB each). CI does not run it.
# Needs: the `sim` and `analyze` binaries (built here with `cargo build --workspace --all-features --profile test --bins`,
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
[ -x "$sim" ] && [ -x "$analyze" ] || cargo build --workspace --all-features --profile test --bins --quiet

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$sim" -q -o "$tmp" > /dev/null
"$sim" run docs/src/how-to/contact-shapes/shapes.json -q -o "$tmp" > /dev/null
# name, recording, tab
shots=(
  "two-elbow paper-two-elbow arm"
  "unilateral paper-unilateral-two-elbow-unilateral arm"
  "unilateral-slip paper-unilateral-two-elbow-unilateral slip / stick"
  "shapes shapes-bodies arm"
)
for shot in "${shots[@]}"; do
  read -r name rec tab <<< "$shot"
  "$analyze" view -q "$tmp/$rec.mcap" -o "$tmp/$name.rrd" --tab "$tab"
  for size in 1440x900 1920x1080; do
    VK_ICD_FILENAMES="$lvp" xvfb-run -a -s "-screen 0 ${size}x24" \
      "$rerun" "$tmp/$name.rrd" --window-size "$size" --screenshot-to "$tmp/$name-$size.png" > "$tmp/$name-$size.log" 2>&1
    pngquant --force --quality 50-80 --output "docs/src/images/rerun-$name-$size.png" "$tmp/$name-$size.png"
  done
done
ls -l docs/src/images/rerun-*.png
du -ch docs/src/images/rerun-*.png | tail -1
