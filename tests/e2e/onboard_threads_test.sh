#!/usr/bin/env bash
# Every thread of the robot in one run, for the sanitizer presets (TSan, ASan + UBSan stop the
# process at their first report): semap-onboard on the simulated rig for 20 s with the GNSS
# driver on its pty, the camera feed, the estimation, perception and mapping stages, the
# checkpoint writer, the map pager (a memory radius the figure-eight leaves) and the map
# publisher, while a planner-side semap-map-listener joins 8 s late over DDS on loopback; then
# SIGTERM. Frames are painted in class colours for the palette segmenter, so the run exercises
# semap's threads rather than OpenCV's network, and the map is updated by the mapping thread
# alone (map.threads: 1): Debian's TBB is not built with TSan, which would otherwise report every
# hand-off of the insert to a TBB worker. Passes when:
# - semap-onboard exits 0 with its map saved, and no sanitizer reported anything;
# - the listener received blocks and rejected none;
# - the summary's counts agree stage to stage: every colour frame taken is a cloud or counted
#   with its reason, and every cloud is in the map or counted as dropped by the cloud ring.
set -euo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/stage_counts.sh"
onboard="$1" listener="$2" config="$3" xml="$4"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
ns="threads$$"
work=$(mktemp -d)
trap 'kill -9 ${pids:-} 2>/dev/null || true; rm -rf "$work"' EXIT
fail() { echo "e2e: $*"; exit 1; }
num() { [[ "$2" =~ ^[0-9]+$ ]] || fail "$1: '$2' is not a count"; }

sed -e "s#save_path: .*#save_path: $work/map.smap#" -e "s#^dds:#dds:\n  namespace: $ns#" \
  -e "s#camera_image: .*#camera_image: classes#" -e "s#kind: onnx .*#kind: palette#" \
  -e "s#^  model_card: .*##" -e "s#^  checkpoint_s: .*#  checkpoint_s: 2\n  memory_radius_m: 20#" \
  -e "s#^  threads: .*#  threads: 1#" \
  "$config" >"$work/sim.yaml"
for want in "namespace: $ns" "camera_image: classes" "kind: palette" "memory_radius_m: 20" \
  "threads: 1"; do
  grep -q "$want" "$work/sim.yaml" || fail "could not write the run's config ($want)"
done

"$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" >"$work/onboard.log" 2>&1 &
onboard_pid=$!
(
  sleep 8
  exec "$listener" --domain "$domain" --ns "$ns" --seconds 90 --classes 8 >"$work/listener.log" 2>&1
) &
listener_pid=$!
pids="$onboard_pid $listener_pid"
sleep 20
kill -TERM "$onboard_pid" 2>/dev/null || echo "e2e: semap-onboard had already exited"
status=0
wait "$onboard_pid" || status=$?
sleep 2 # the listener takes the robot's last blocks
kill -TERM "$listener_pid" 2>/dev/null || true
wait "$listener_pid" || { cat "$work/listener.log"; fail "the listener failed"; }
sed -n '/summary/,$p' "$work/onboard.log"
if grep -qE "Sanitizer|runtime error" "$work/onboard.log"; then
  cat "$work/onboard.log"
  fail "a sanitizer reported"
fi
[[ $status -eq 0 ]] || { cat "$work/onboard.log"; fail "semap-onboard exited with $status on SIGTERM"; }
grep -q "map saved to $work/map.smap" "$work/onboard.log" || fail "no map saved at SIGTERM"

last=$(grep '^final: ' "$work/listener.log" | tail -1)
blocks=$(awk '{print $3}' <<<"$last") rejected=$(awk '{print $7}' <<<"$last")
num "listener blocks" "$blocks"
num "listener rejected" "$rejected"
[[ "$blocks" -gt 0 && "$rejected" -eq 0 ]] || fail "listener: $last"

check_stage_counts "$work/onboard.log"
[[ "$scans" -gt 0 ]] || fail "nothing mapped"
echo "e2e: every thread ran: $frames frames, $posed clouds, $scans mapped, $blocks blocks received"
