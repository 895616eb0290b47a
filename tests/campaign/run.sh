#!/usr/bin/env bash
# The adversarial campaign of TESTING.md ("Robustness"), as one command a reviewer can re-run:
#
#   tests/campaign/run.sh                 # the full campaign (about 40 min on 2 cores)
#   tests/campaign/run.sh --quick         # a tenth of every count (a smoke test of the script)
#   tests/campaign/run.sh races kills     # some parts only
#
# Parts (each prints its counts; any failure stops the script with exit 1):
#   scenes      FUZZ_CASES generated scenes and URDFs through validation and runs (sim's fuzz test)
#   recordings  FUZZ_CASES damaged recordings through the reading path of every analyze command
#               (analyze's fuzz test: no panic, an error naming the file, or the intact numbers)
#   commands    damaged and hostile files through every `analyze` command as a process, with a
#               wall-time limit (a hang fails) and the peak memory of each (over 200 MB fails)
#   races       8 `sim` processes writing one recording at once (0 corrupt files, 0 leftovers)
#   kills       `sim` killed (SIGKILL) at random times: no final file, the next run cleans up,
#               and `analyze metrics --recover` on the partial file reads or refuses, never panics
#   disks       full disks (a tmpfs of 8 KiB to 4 MiB) under `sim` and `analyze export`: exit 2
#               naming the path, nothing half-written under a final name
#
# Exit statuses that fail a part: 101 (a Rust panic), 124 (killed by the time limit: a hang),
# 128+n (killed by a signal), and any exit with "panicked" on standard error.
#
# Needs: release binaries (built here with `cargo build --release --bins`), python3 (the damaged
# files), GNU time (/usr/bin/time, for peak memory), `unshare -rm` for the disks part.
set -euo pipefail
cd "$(dirname "$0")/../.."

scale=1
parts=()
for a in "$@"; do
  case "$a" in
    --quick) scale=10 ;;
    scenes|recordings|commands|races|kills|disks) parts+=("$a") ;;
    *) echo "usage: $0 [--quick] [scenes|recordings|commands|races|kills|disks ...]" >&2; exit 2 ;;
  esac
done
[ ${#parts[@]} -gt 0 ] || parts=(scenes recordings commands races kills disks)

export CARGO_TERM_COLOR=never
[ -n "${CAMPAIGN_NO_BUILD:-}" ] || cargo build --release --bins --all-features --quiet
target="${CARGO_TARGET_DIR:-target}"
SIM="$(realpath "$target/release/sim")"
ANALYZE="$(realpath "$target/release/analyze")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
small=sim/scenes/small/small.json

fail() { echo "campaign: FAILED: $*" >&2; exit 1; }

# $1: label, $2: exit status, $3: stderr file. Fails on a panic, a hang or a signal.
judge() {
  local label="$1" code="$2" err="$3"
  if grep -q "panicked" "$err"; then fail "$label: a panic: $(head -c 600 "$err")"; fi
  case "$code" in
    101) fail "$label: exit 101 (a panic): $(head -c 600 "$err")" ;;
    124) fail "$label: a hang (killed by the time limit)" ;;
  esac
  [ "$code" -lt 128 ] || fail "$label: killed by signal $((code - 128)): $(head -c 600 "$err")"
}

part_scenes() {
  local n=$((10000 / scale))
  echo "== scenes: $n generated scenes, $((n / 5)) URDFs (seed 29)"
  FUZZ_CASES=$n FUZZ_SEED=29 cargo test --quiet -p sim --test all fuzz_scenes -- --nocapture 2>&1 | grep -E "scenes|URDFs|test result" || fail "scenes"
}

part_recordings() {
  local n=$((100000 / scale))
  echo "== recordings: $n damaged recordings through every command's reading path (seed 29)"
  FUZZ_CASES=$n FUZZ_SEED=29 cargo test --quiet -p analyze --test fuzz_read -- --nocapture 2>&1 | grep -vE "^$|^running" || fail "recordings"
}

# Damaged copies of a real recording and hostile files, then every command on each.
part_commands() {
  local n=$((500 / scale)) d="$work/commands"
  mkdir -p "$d/in" "$d/out"
  "$SIM" run "$small" --run free --duration 0.5 --quiet -o "$d/good" > /dev/null
  local good
  good="$(ls "$d"/good/*.mcap | head -1)"
  python3 - "$good" "$d/in" "$n" <<'EOF'
import os, random, sys
src, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
base = open(src, 'rb').read()
r = random.Random(29)
for k in range(n):
    b = bytearray(base)
    kind = k % 6
    if kind == 0:   # truncated
        b = b[:r.randrange(len(b))]
    elif kind == 1: # bit flips
        for _ in range(r.randint(1, 8)):
            i = r.randrange(len(b)); b[i] ^= 1 << r.randrange(8)
    elif kind == 2: # a record length field made huge
        i = r.randrange(8, len(b) - 9); b[i + 1:i + 9] = r.choice([2**63, 2**40, 2**31, 5002 * 8]).to_bytes(8, 'little')
    elif kind == 3: # a span deleted
        i = r.randrange(len(b)); b = b[:i] + b[i + r.randrange(1, 4096):]
    elif kind == 4: # a span repeated
        i = r.randrange(len(b)); j = min(len(b), i + r.randrange(1, 65536)); b = b[:j] + b[i:j] + b[j:]
    else:           # random bytes behind the magic
        b = b[:8] + bytearray(r.randbytes(r.randrange(1, 20000)))
    open(os.path.join(out, f'damaged-{k:05}.mcap'), 'wb').write(b)
EOF
  # hostile files: a sparse 20 GB non-MCAP file, a link to /dev/zero, a FIFO, a directory
  truncate -s 20G "$d/in/sparse-20g.mcap"
  ln -s /dev/zero "$d/in/zero.mcap"
  mkfifo "$d/in/fifo.mcap"
  mkdir "$d/in/dir.mcap"
  local cmds=("metrics" "metrics --recover" "compare" "summary" "report -o $d/out/report" "figures -o $d/out/figures" \
              "export -o $d/out/export" "export --format csv -o $d/out/export" "view -o $d/out/view.rrd" "layout -o $d/out" "diff $good")
  local runs=0 refused=0 read_ok=0 peak=0
  for f in "$d"/in/*; do
    for c in "${cmds[@]}"; do
      # shellcheck disable=SC2086
      set -- $c
      local sub="$1"; shift
      local code=0
      /usr/bin/time -f "%M" -o "$d/rss" timeout 60 "$ANALYZE" --quiet "$sub" "$@" "$f" > /dev/null 2> "$d/err" || code=$?
      judge "analyze $c $f" "$code" "$d/err"
      local kb; kb="$(tail -1 "$d/rss" | tr -dc 0-9)"; kb="${kb:-0}"
      [ "$kb" -le 204800 ] || fail "analyze $c $f: peak memory $((kb / 1024)) MB (limit 200 MB)"
      [ "$kb" -le "$peak" ] || peak=$kb
      runs=$((runs + 1))
      if [ "$code" = 0 ]; then read_ok=$((read_ok + 1)); else refused=$((refused + 1)); fi
      rm -rf "$d/out"/*
    done
  done
  echo "commands: $runs runs of ${#cmds[@]} commands on $(ls "$d/in" | wc -l) files: $read_ok exit 0, $refused refused (exit 1 or 2), 0 panics, 0 hangs, peak memory $((peak / 1024)) MB"
}

part_races() {
  local trials=$((100 / scale)) racers=8 wrote=0 refused=0
  echo "== races: $trials trials x $racers sim processes writing one file"
  "$SIM" run "$small" --run free --duration 0.4 --quiet -f json -o "$work/race-ref" > /dev/null
  local ref="$work/race-ref/small-free.mcap"
  for t in $(seq "$trials"); do
    local d="$work/race-$t"; mkdir -p "$d"
    local pids=()
    for k in $(seq "$racers"); do
      "$SIM" run "$small" --run free --duration 0.4 --quiet -f json -o "$d" > /dev/null 2> "$d.err$k" &
      pids+=($!)
    done
    for k in $(seq "$racers"); do
      local code=0
      wait "${pids[$((k - 1))]}" || code=$?
      judge "race $t process $k" "$code" "$d.err$k"
      case "$code" in
        0) wrote=$((wrote + 1)) ;;
        2) grep -q "another process is writing" "$d.err$k" || fail "race $t: exit 2 without the refusal: $(cat "$d.err$k")"; refused=$((refused + 1)) ;;
        *) fail "race $t process $k: exit $code: $(cat "$d.err$k")" ;;
      esac
    done
    cmp -s "$ref" "$d/small-free.mcap" || fail "race $t: the final file differs from a lone run's"
    local left; left="$(ls -A "$d" | grep -v -e '^small-free.mcap$' -e '^small-free.foxglove-layout.json$' || true)"
    [ -z "$left" ] || fail "race $t: left behind: $left"
    rm -rf "$d" "$d".err*
  done
  echo "races: $((trials * racers)) processes: $wrote wrote, $refused refused, 0 corrupt, 0 leftovers"
}

part_kills() {
  local trials=$((40 / scale)) recovered=0 refused=0
  echo "== kills: $trials sim runs killed with SIGKILL at random times"
  for t in $(seq "$trials"); do
    local d="$work/kill-$t"; mkdir -p "$d"
    "$SIM" run sim/scenes/paper.json --run two-elbow --duration 60 --quiet -o "$d" > /dev/null 2>&1 &
    local pid=$!
    sleep "$(python3 -c "import random; random.seed($t); print(round(random.uniform(0.1, 3.0), 3))")"
    kill -9 "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
    [ ! -e "$d/paper-two-elbow.mcap" ] || { rm -rf "$d"; continue; }   # it finished first
    local partial; partial="$(ls -A "$d" | grep '\.partial$' | head -1 || true)"
    if [ -n "$partial" ]; then
      local code=0
      timeout 60 "$ANALYZE" --quiet metrics --recover "$d/$partial" -f json > "$d.out" 2> "$d.err" || code=$?
      judge "metrics --recover of kill $t" "$code" "$d.err"
      # a recovered run is incomplete (exit 1) with its metrics up to the last flush group
      if [ "$code" = 1 ] && python3 -c "import json,sys; m=json.load(open(sys.argv[1]))[0]; sys.exit(0 if m['status']=='incomplete' and (m.get('t_end_s') or 0) > 0 else 1)" "$d.out" 2> /dev/null; then
        recovered=$((recovered + 1))
      else
        [ "$code" = 2 ] || fail "metrics --recover of kill $t: exit $code without recovered metrics: $(head -c 600 "$d.err")"
        refused=$((refused + 1))
      fi
    fi
    # the next run of the same path cleans up and finishes
    local code=0
    "$SIM" run sim/scenes/paper.json --run two-elbow --duration 0.05 --quiet -o "$d" > /dev/null 2> "$d.err" || code=$?
    [ "$code" = 0 ] || fail "the run after kill $t: exit $code: $(cat "$d.err")"
    [ -z "$(ls -A "$d" | grep -e '\.partial$' -e '\.lock$' || true)" ] || fail "kill $t: leftovers after the next run: $(ls -A "$d")"
    rm -rf "$d" "$d".*
  done
  echo "kills: $trials killed: $recovered partial files gave metrics with --recover, $refused refused with a reason, 0 final files, 0 leftovers after the next run"
  # analyze export killed mid-way: what it leaves is marked INCOMPLETE until it is done
  "$SIM" run sim/scenes/paper.json --run two-elbow --duration 30 --quiet -o "$work/kill-src" > /dev/null
  local marked=0 finished=0
  for t in $(seq "$trials"); do
    local d="$work/kill-export-$t"
    "$ANALYZE" --quiet export "$work/kill-src/paper-two-elbow.mcap" --format csv -o "$d" > /dev/null 2>&1 &
    local pid=$!
    sleep "$(python3 -c "import random; random.seed(1000 + $t); print(round(random.uniform(0.02, 1.0), 3))")"
    kill -9 "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
    local tables="$d/paper-two-elbow"
    if [ -d "$tables" ] && [ -n "$(ls -A "$tables")" ]; then
      if [ -e "$tables/INCOMPLETE" ]; then marked=$((marked + 1));
      else [ -e "$tables/metadata.json" ] || fail "export killed ($t): tables without metadata.json and without INCOMPLETE: $(ls "$tables")"; finished=$((finished + 1)); fi
    fi
    rm -rf "$d"
  done
  echo "kills: $trials analyze export killed: $marked left tables marked INCOMPLETE, $finished had finished, 0 unmarked partial exports"
}

part_disks() {
  echo "== disks: sim and analyze export on full tmpfs disks"
  unshare -rm true 2> /dev/null || { echo "disks: unshare -rm is not available here"; [ "${CI:-}" != true ] || fail "disks: no unshare under CI"; return; }
  "$SIM" run "$small" --run free --duration 0.5 --quiet -o "$work/disk-src" > /dev/null
  local src; src="$(ls "$work"/disk-src/*.mcap | head -1)"
  local n=0
  for kb in 8 16 32 64 128 256 512 1024 2048 4096; do
    for what in sim export; do
      local d="$work/disk-$kb-$what" code=0
      mkdir -p "$d"
      if [ "$what" = sim ]; then
        unshare -rm sh -c "mount -t tmpfs -o size=${kb}k tmpfs '$d' && '$SIM' run '$small' --run free --duration 0.5 --quiet -o '$d/out' > /dev/null 2> '$work/disk.err'; c=\$?; ls -A '$d/out' > '$work/disk.ls' 2>/dev/null; exit \$c" || code=$?
      else
        unshare -rm sh -c "mount -t tmpfs -o size=${kb}k tmpfs '$d' && '$ANALYZE' --quiet export '$src' -o '$d/out' > /dev/null 2> '$work/disk.err'; c=\$?; (cd '$d/out' 2>/dev/null && find . -type f) > '$work/disk.ls' 2>/dev/null; exit \$c" || code=$?
      fi
      judge "$what on a ${kb} KiB disk" "$code" "$work/disk.err"
      case "$code" in
        0) ;;
        2) grep -qi "no space" "$work/disk.err" || fail "$what on a ${kb} KiB disk: exit 2 without the OS reason: $(cat "$work/disk.err")"
           ! grep -q '\.mcap$' "$work/disk.ls" || fail "$what on a ${kb} KiB disk: a recording left under its final name: $(cat "$work/disk.ls")"
           # an export cut short is marked INCOMPLETE (or left nothing)
           if [ "$what" = export ] && [ -s "$work/disk.ls" ]; then
             grep -q 'INCOMPLETE$' "$work/disk.ls" || fail "export on a ${kb} KiB disk: tables left without the INCOMPLETE mark: $(cat "$work/disk.ls")"
           fi ;;
        *) fail "$what on a ${kb} KiB disk: exit $code: $(cat "$work/disk.err")" ;;
      esac
      n=$((n + 1))
      rm -rf "$d"
    done
  done
  echo "disks: $n runs on full disks: every one exit 0 or exit 2 with the OS reason, no recording under a final name after a failure"
}

for p in "${parts[@]}"; do
  "part_$p"
done
echo "campaign: passed (${parts[*]})"
