#!/usr/bin/env bash
# kill -9 in the middle of a run, then --resume: semap-onboard on the simulated rig writes its
# map checkpoint every second; once the checkpoint holds a mapped stretch the process is killed
# with SIGKILL and a torn record is appended (a write the kill interrupted). The second run must
# cut the torn record, resume the checkpoint's blocks and scans, anchor its frame where the
# first run did, keep mapping and save the map at exit.
set -euo pipefail
onboard="$1" config="$2" xml="$3"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
work=$(mktemp -d)
trap 'kill -9 "${pid:-0}" 2>/dev/null || true; rm -rf "$work"' EXIT
fail() { echo "e2e resume: $*"; exit 1; }

sed -e "s#save_path: .*#save_path: $work/map.smap\n  checkpoint_s: 1#" "$config" >"$work/sim.yaml"
grep -q "checkpoint_s: 1" "$work/sim.yaml" || fail "could not set map.checkpoint_s"

"$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" >"$work/first.log" 2>&1 &
pid=$!
# Mapping starts once the heading is known (about 15 s); wait for 1 MB of checkpoint.
for _ in $(seq 1 90); do
  size=$(stat -c %s "$work/map.smap.log" 2>/dev/null || echo 0)
  [[ $size -gt 1000000 ]] && break
  kill -0 "$pid" 2>/dev/null || { cat "$work/first.log"; fail "first run ended early"; }
  sleep 1
done
[[ $size -gt 1000000 ]] || { cat "$work/first.log"; fail "no checkpoint after 90 s"; }
sleep 3
kill -9 "$pid"
wait "$pid" 2>/dev/null || true
first_anchor=$(grep -o "anchored at [-0-9.]*, [-0-9.]*" "$work/first.log" | head -1 | sed 's/anchored at //')
# The start of a block record, cut short by the kill.
printf '\001\000\000\000\174\000\000\000torn' >>"$work/map.smap.log"

"$onboard" --config "$work/sim.yaml" --duration 25 --domain "$domain" --resume \
  >"$work/second.log" 2>&1 || { cat "$work/second.log"; fail "the resumed run failed"; }
grep -E "checkpoint|resumed|anchored|mapping  " "$work/second.log"

grep -q "map checkpoint: .*record at byte [0-9]*: " "$work/second.log" ||
  fail "the damaged record was not reported"
resumed=$(grep -o "map resumed from .*: [0-9]* blocks of [0-9]* scans" "$work/second.log") ||
  fail "no resume line"
blocks=$(echo "$resumed" | sed 's/.*: \([0-9]*\) blocks of \([0-9]*\) scans/\1/')
scans=$(echo "$resumed" | sed 's/.*: \([0-9]*\) blocks of \([0-9]*\) scans/\2/')
[[ $blocks -gt 100 && $scans -gt 10 ]] || fail "resumed only $blocks blocks of $scans scans"
grep -q "map frame anchored at $first_anchor" "$work/second.log" ||
  fail "the resumed frame is not the first run's ($first_anchor)"
final_blocks=$(grep -o "mapping  .* \([0-9]*\) blocks" "$work/second.log" | grep -o "[0-9]* blocks" |
  grep -o "[0-9]*")
[[ $final_blocks -ge $blocks ]] || fail "the map shrank from $blocks to $final_blocks blocks"
[[ -s "$work/map.smap" ]] || fail "no map saved at exit"
echo "e2e resume: resumed $blocks blocks of $scans scans, $final_blocks blocks at exit"
