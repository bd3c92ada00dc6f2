#!/usr/bin/env bash
# SIGTERM in the middle of saving, then --resume (docs/reliability.md). semap-onboard on the
# simulated rig checkpoints its map every 0.2 s (a write takes 50-100 ms here), so the signal
# often lands while the checkpoint writer is writing:
# 1. SIGTERM, and a second one 50 ms later while the stages drain and the map is saved: the
#    robot finishes its checkpoint, flushes the rest, saves the map and exits 0; --resume then
#    loads exactly the map it had (the summary's scans and blocks).
# 2. A resumed run is stopped with SIGTERM and killed with SIGKILL while it writes the map at
#    exit (systemd's TimeoutStopSec): the map file is the earlier complete one, and --resume
#    loads at least the blocks the run had reported and more scans than it started with.
set -euo pipefail
onboard="$1" config="$2" xml="$3"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
work=$(mktemp -d)
trap 'kill -9 "${pid:-0}" 2>/dev/null || true; rm -rf "$work"' EXIT
fail() {
  echo "e2e sigterm save: $*"
  exit 1
}
say() { echo "e2e sigterm save: $*"; }

sed -e "s#save_path: .*#save_path: $work/map.smap\n  checkpoint_s: 0.2#" "$config" >"$work/sim.yaml"
grep -q "checkpoint_s: 0.2" "$work/sim.yaml" || fail "could not set map.checkpoint_s"

# start NAME [flags]: semap-onboard in the background, its output in NAME.log.
start() {
  local name="$1"
  shift
  "$onboard" --config "$work/sim.yaml" --domain "$domain" "$@" >"$work/$name.log" 2>&1 &
  pid=$!
}
# wait_mapping NAME BYTES: until the checkpoint log holds BYTES, while the robot runs.
wait_mapping() {
  for _ in $(seq 1 120); do
    [[ $(stat -c %s "$work/map.smap.log" 2>/dev/null || echo 0) -gt $2 ]] && return 0
    kill -0 "$pid" 2>/dev/null || {
      cat "$work/$1.log"
      fail "$1 ended early"
    }
    sleep 1
  done
  fail "$1: no checkpoint of $2 bytes after 120 s"
}
# wait_blocks NAME N: until the progress line reports more than N blocks in the map.
wait_blocks() {
  for _ in $(seq 1 120); do
    local now
    now=$(grep -o "| blocks [0-9]* |" "$work/$1.log" | tail -1 | grep -o "[0-9]*" || echo 0)
    [[ ${now:-0} -gt $2 ]] && return 0
    kill -0 "$pid" 2>/dev/null || {
      cat "$work/$1.log"
      fail "$1 ended early"
    }
    sleep 1
  done
  fail "$1: not more than $2 blocks after 120 s"
}
# resumed NAME: "blocks scans" of the resume line.
resumed() {
  grep -o "map resumed from $work/map.smap.log: [0-9]* blocks of [0-9]* scans" "$work/$1.log" |
    sed 's/.*: \([0-9]*\) blocks of \([0-9]*\) scans/\1 \2/'
}
check_resume() { # NAME: a short resumed run; the log must have no torn record
  "$onboard" --config "$work/sim.yaml" --domain "$domain" --resume --duration 3 \
    >"$work/$1.log" 2>&1 || true
  grep -q "map checkpoint: .*record at byte" "$work/$1.log" && fail "$1: a torn record in the log"
  [[ -n $(resumed "$1") ]] || {
    cat "$work/$1.log"
    fail "$1: did not resume"
  }
}

# 1. Two SIGTERMs while checkpointing and saving.
start first --duration 120
wait_mapping first 1000000
sleep 2
kill -TERM "$pid"
sleep 0.05
kill -TERM "$pid" 2>/dev/null || true
status=0
wait "$pid" || status=$?
[[ $status -eq 0 ]] || {
  cat "$work/first.log"
  fail "exit status $status after SIGTERM"
}
grep -q "map saved to $work/map.smap" "$work/first.log" || fail "the map was not saved"
grep -q "checkpoint fails" "$work/first.log" && fail "a checkpoint failed"
summary=$(grep -o "^mapping          : [0-9]* scans, .*, [0-9]* blocks," "$work/first.log")
scans=$(echo "$summary" | sed 's/^mapping *: \([0-9]*\) scans.*/\1/')
blocks=$(echo "$summary" | sed 's/.*, \([0-9]*\) blocks,$/\1/')
check_resume second
read -r got_blocks got_scans <<<"$(resumed second)"
[[ $got_blocks -eq $blocks && $got_scans -eq $scans ]] ||
  fail "resumed $got_blocks blocks of $got_scans scans; the run had $blocks of $scans"
say "SIGTERM x2: exit 0, resumed all $got_blocks blocks of $got_scans scans"
saved_size=$(stat -c %s "$work/map.smap")

# 2. SIGKILL while the map is written at exit.
start third --duration 120 --resume
wait_blocks third $((blocks + 500))
sleep 2
kill -TERM "$pid"
caught=no
for _ in $(seq 1 3000); do # 30 s: the stages drain, the checkpoint flushes, the map is saved
  if compgen -G "$work/.map.smap.*" >/dev/null; then
    kill -9 "$pid"
    caught=yes
    break
  fi
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.01
done
wait "$pid" 2>/dev/null || true
last_blocks=$(grep -o "| blocks [0-9]* |" "$work/third.log" | tail -1 | grep -o "[0-9]*")
if [[ $caught == yes ]]; then
  # The save never replaced the map: the file is the one the second run saved, whole.
  [[ $(stat -c %s "$work/map.smap") -eq $saved_size ]] || fail "a killed save changed the map"
fi
check_resume fourth
read -r got_blocks got_scans <<<"$(resumed fourth)"
[[ $got_blocks -ge $last_blocks && $got_scans -gt $scans ]] ||
  fail "resumed $got_blocks blocks of $got_scans scans after the kill; the run had reported" \
    "$last_blocks blocks and started from $scans scans"
say "SIGKILL during the save at exit (caught in the save: $caught): resumed $got_blocks blocks" \
  "(>= $last_blocks reported) of $got_scans scans (> $scans)"
