#!/usr/bin/env bash
# Re-make the archived paper runs, their energy table, their Foxglove layouts and the manifest.
#   recordings/refresh.sh           refresh the archive in place (then review and commit the diff)
#   recordings/refresh.sh --check   re-make into a temporary directory and compare with the archive
#                                   (byte for byte, and the energy table line by line); exit 1 if
#                                   anything differs. CI runs this.
# Needs the release binaries: `cargo build --release --bins` (CARGO_TARGET_DIR honoured).
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-target}"
sim="$(realpath -m "$target")/release/sim"
analyze="$(realpath -m "$target")/release/analyze"
[ -x "$sim" ] && [ -x "$analyze" ] || cargo build --release --bins --quiet

make_archive() {  # $1 = output directory
  local dir="$1"
  mkdir -p "$dir"
  "$sim" run recordings/paper-archive.json -o "$dir" -j 1 --quiet --format csv > /dev/null
  # from inside the directory, so the table names the files without a directory
  (cd "$dir" && "$analyze" compare paper-archive-*.mcap --format csv > paper-archive-energy.csv)
  {
    echo "{"
    echo "  \"scene\": \"recordings/paper-archive.json\","
    echo "  \"scene_sha256\": \"$(sha256sum recordings/paper-archive.json | cut -d' ' -f1)\","
    echo "  \"urdf_sha256\": \"$(sha256sum sim/scenes/paper_arm.urdf | cut -d' ' -f1)\","
    # the tool's name and version as recordings store them (not the build's commit)
    echo "  \"tool\": \"$("$sim" --version | cut -d' ' -f1,2)\","
    echo "  \"command\": \"sim run recordings/paper-archive.json -o recordings -j 1\","
    echo "  \"files\": ["
    local first=1
    for f in "$dir"/paper-archive-*.mcap "$dir/paper-archive-energy.csv" "$dir"/paper-archive-*.foxglove-layout.json; do
      [ $first = 1 ] || echo ","
      first=0
      printf '    {"name": "%s", "bytes": %s, "sha256": "%s"}' "$(basename "$f")" "$(stat -c %s "$f")" "$(sha256sum "$f" | cut -d' ' -f1)"
    done
    echo
    echo "  ]"
    echo "}"
  } > "$dir/MANIFEST.json"
}

if [ "${1:-}" = "--check" ]; then
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
  # the archived recordings reproduce themselves from their own metadata ...
  for f in recordings/paper-archive-*.mcap; do
    "$sim" replay "$f" -o "$tmp/replay" --quiet > /dev/null
    cmp "$f" "$tmp/replay/$(basename "$f")"
  done
  # ... and the current code re-makes them from the scene
  make_archive "$tmp/new"
  status=0
  for f in recordings/paper-archive-*.mcap recordings/paper-archive-energy.csv recordings/paper-archive-*.foxglove-layout.json recordings/MANIFEST.json; do
    if ! cmp -s "$f" "$tmp/new/$(basename "$f")"; then
      echo "archive: $(basename "$f") differs from a fresh run" >&2
      status=1
    fi
  done
  if [ $status != 0 ]; then
    # what moved, per run and per link (analyze diff exits 1 when something did)
    "$analyze" diff recordings "$tmp/new" >&2 || true
    echo "archive: the physics or the format changed. If that is intended, run recordings/refresh.sh and commit the new archive." >&2
    exit 1
  fi
  echo "archive: 3 recordings, energy table and manifest reproduced exactly"
else
  make_archive recordings
  echo "archive refreshed; review with git diff --stat recordings/ and commit"
fi
