#!/usr/bin/env bash
# A shortened scripts/demo: semap-onboard on the simulated rig for 20 s with --report, while a
# planner-side semap-map-listener joins 8 s late over DDS on loopback. Passes when:
# - summary.json holds the demo's figures within margins: pose RMSE <= 0.5 m, >= 10 frames
#   mapped per second of drive, segmentation and map mIoU above the thresholds below, no
#   drops in the IMU and GNSS rings, plausible latency and CPU;
# - the report's files exist and load: semap-export reads map.smap (and exports it), the PNGs
#   are whole PNG files;
# - the late-joining listener received the whole map: every block, and the same occupied
#   cells with the same classes as the saved map (agreement);
# - the robot's own health figures hold: it initialised, perception turned the camera frames
#   into posed clouds and the map took (nearly) every one, the listener saw no rejected
#   blocks and plausible rt/semap/health reports.
set -euo pipefail
onboard="$1" listener="$2" config="$3" xml="$4" exporter="$5"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
report="$work/report"
duration=30

# Thresholds per segmenter, measured on this 2-core machine (30 s runs, with margin; the
# rendered frames are deterministic, the poses nearly so):
# - palette on class-painted frames (a perfect segmenter): segmentation mIoU 1.000, map 0.769;
# - onnx (models/semap-seg.onnx on rendered frames): segmentation mIoU 0.832, map mIoU 0.701;
#   a retrained model needs these looked at again.
# map_miou scores every occupied cell against the world's class within its half-diagonal, so
# cells that the S-BKI kernel, depth noise and pose error put next to a surface count against it.
min_seg_palette=0.99 min_map_palette=0.65
min_seg_onnx=0.75 min_map_onnx=0.6

(
  sleep 8
  exec "$listener" --domain "$domain" --seconds 60 --classes 8 --health \
    --save "$work/received.pcd" >"$work/listener.log" 2>&1
) &
listener_pid=$!
rm -f build/sim_map.smap
"$onboard" --config "$config" --duration "$duration" --domain "$domain" --report "$report" \
  >"$work/onboard.log" 2>&1 || {
  echo "semap-onboard failed"
  cat "$work/onboard.log"
  exit 1
}
sleep 2 # the listener takes the robot's last blocks
kill -TERM "$listener_pid" 2>/dev/null || true
wait "$listener_pid" || { echo "listener failed"; cat "$work/listener.log"; exit 1; }

sed -n '/summary/,$p' "$work/onboard.log"
cat "$report/summary.json"
tail -3 "$work/listener.log"
fail() { echo "e2e: $*"; exit 1; }
at_least() { awk -v v="$1" -v m="$2" 'BEGIN { exit !(v != "" && v != "null" && v + 0 >= m + 0) }'; }
at_most() { awk -v v="$1" -v m="$2" 'BEGIN { exit !(v != "" && v != "null" && v + 0 <= m + 0) }'; }
json() { # json KEY: the number after "KEY": in summary.json (first match)
  grep -o "\"$1\": [-0-9.a-z]*" "$report/summary.json" | head -1 | sed 's/.*: //'
}

# The report's files.
for f in summary.json map.smap camera.png trajectory.png; do
  [[ -s "$report/$f" ]] || fail "report has no $f"
done
"$exporter" "$report/map.smap" --png "$work/top.png" --variance-png "$work/variance.png" \
  --ply "$work/map.ply" --palette "$(dirname "$config")/sim-classes.yaml" --compare "$work/received.pcd" \
  >"$work/export.log" 2>&1 || { cat "$work/export.log"; fail "semap-export failed on map.smap"; }
[[ -s "$work/map.ply" ]] || fail "export wrote no PLY"
for png in "$report/camera.png" "$report/trajectory.png" "$work/top.png" "$work/variance.png"; do
  # The PNG signature first and the IEND chunk last: a whole file.
  [[ $(head -c 8 "$png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a &&
    $(tail -c 8 "$png" | head -c 4) == IEND ]] || fail "$png is not a whole PNG"
done

# summary.json.
segmenter=$(sed -n 's/.*"segmenter": "\([a-z]*\)".*/\1/p' "$report/summary.json")
case "$segmenter" in
  palette) min_seg=$min_seg_palette min_map=$min_map_palette ;;
  onnx) min_seg=$min_seg_onnx min_map=$min_map_onnx ;;
  *) fail "segmenter '$segmenter'" ;;
esac
rmse=$(json pose_rmse_m)
at_most "$rmse" 0.5 || fail "pose RMSE $rmse m > 0.5 m"
mapped=$(json frames_mapped) captured=$(json frames_captured)
# The camera runs at 15 Hz; frames before the filter's heading settles get no pose. Every
# frame after that must reach the map (a few may be passed over).
unposed=$(sed -n 's/^perception *: .* \([0-9]*\) without a pose.*/\1/p' "$work/onboard.log")
at_least "$captured" $((14 * duration)) || fail "$captured frames captured in $duration s"
at_least "$((mapped * 100))" $(((captured - unposed) * 95)) ||
  fail "$mapped frames mapped of $((captured - unposed)) with a pose"
at_least "$mapped" $((4 * duration)) || fail "only $mapped frames mapped"
seg=$(json segmentation_miou) map=$(json map_miou)
at_least "$seg" "$min_seg" || fail "segmentation mIoU $seg < $min_seg ($segmenter)"
at_least "$map" "$min_map" || fail "map mIoU $map < $min_map ($segmenter)"
[[ $(json imu) == 0 && $(json gnss) == 0 ]] || fail "driver ring drops: $(grep ring_drops "$report/summary.json")"
p50=$(json p50) p99=$(json p99)
awk -v a="$p50" -v b="$p99" 'BEGIN { exit !(a > 0 && b >= a && b < 1000) }' ||
  fail "frame-to-map latency p50 $p50 p99 $p99 ms"
cores=$(json cpu_cores_used)
awk -v c="$cores" 'BEGIN { exit !(c > 0.1 && c <= 2.5) }' || fail "cpu_cores_used $cores"

# The late joiner has the whole map: the robot's blocks (the last round before exit may be
# cut short: 1% leeway) and the same occupied cells with the same classes.
last=$(grep '^final: ' "$work/listener.log" | tail -1)
blocks=$(awk '{print $3}' <<<"$last")
rejected=$(awk '{print $7}' <<<"$last")
robot_blocks=$(sed -n 's/^mapping *: .*, \([0-9]*\) blocks,.*/\1/p' "$work/onboard.log")
[[ -n "$blocks" && -n "$robot_blocks" && $((blocks * 100)) -ge $((robot_blocks * 99)) &&
  "$rejected" -eq 0 ]] ||
  fail "listener: $last; the robot's map has $robot_blocks blocks"
agreement=$(sed -n 's/^agreement //p' "$work/export.log")
at_least "$agreement" 0.99 || fail "received map vs saved map: $(tr '\n' ' ' <"$work/export.log")"

# The robot's health, as before the report existed.
grep -q "gated out), initialised=yes" "$work/onboard.log" || fail "not initialised"
# The costmap for nav2 went out, rebuilt around the robot as it drove and updated between.
costmap=$(grep '^costmap ' "$work/onboard.log" || true)
grids=$(awk '{print $3}' <<<"$costmap")
[[ -n "$grids" && "$grids" -ge 5 ]] || fail "costmap: '$costmap'"
scans=$(sed -n 's/^mapping *: \([0-9]*\) scans.*/\1/p' "$work/onboard.log")
posed=$(sed -n 's/^perception *: [0-9]* frames, \([0-9]*\) clouds mapped.*/\1/p' "$work/onboard.log")
[[ -n "$posed" && "$posed" -eq "$mapped" ]] || fail "perception: $posed clouds, report: $mapped"
# The cloud ring drops the oldest scan rather than stall perception; allow a few drops.
[[ $((scans * 10)) -ge $((posed * 9)) ]] || fail "scans $scans, posed $posed"
field() { # field LINE KIND NAME KEY: the value after "KIND NAME ... KEY" within that entry
  awk -v kind="$2" -v name="$3" -v key="$4" '{
    for (i = 1; i < NF; i++) if ($i == kind && $(i + 1) == name) {
      for (j = i + 2; j < NF && $j != "|"; j++) if ($j == key) { print $(j + 1); exit }
    } }' <<<"$1"
}
reports=$(grep -c '^health: ' "$work/listener.log" || true)
[[ "$reports" -ge 3 ]] || fail "only $reports health reports"
health=$(grep '^health: ' "$work/listener.log" | tail -1)
est_rate=$(field "$health" stage estimation rate)
est_p50=$(field "$health" stage estimation p50)
est_p99=$(field "$health" stage estimation p99)
map_drops=$(field "$health" stage mapping drops)
perc_rate=$(field "$health" stage perception rate)
perc_p99=$(field "$health" stage perception p99)
gnss_frames=$(field "$health" driver gnss frames)
gnss_bad=$(field "$health" driver gnss bad)
awk -v r="$est_rate" -v a="$est_p50" -v b="$est_p99" 'BEGIN { exit !(r > 50 && b >= a && b < 1000) }' ||
  fail "estimation health implausible: $health"
grep '^health: ' "$work/listener.log" | awk '{ for (i = 1; i < NF; i++) if ($i == "mapping" && $(i + 2) > 0) ok = 1 }
  END { exit !ok }' || fail "mapping rate never > 0 in health"
[[ "$gnss_frames" -gt 0 && "$gnss_bad" -eq 0 ]] || fail "gnss driver health: $health"
awk -v r="$perc_rate" -v b="$perc_p99" 'BEGIN { exit !(r > 2 && b > 0 && b < 1000) }' ||
  fail "perception health implausible: $health"
# Ring drops in the health report are the rings' own counters: never more than at exit.
cloud_drops=$(sed -n 's/^ring drops .* clouds \([0-9]*\)$/\1/p' "$work/onboard.log")
[[ -n "$map_drops" && -n "$cloud_drops" && "$map_drops" -le "$cloud_drops" ]] ||
  fail "mapping drops $map_drops vs cloud ring drops at exit '$cloud_drops'"
echo "e2e: last $health"
echo "e2e: $segmenter segmenter: pose RMSE $rmse m, segmentation mIoU $seg, map mIoU $map," \
  "$mapped frames mapped, latency p50 $p50 p99 $p99 ms, listener $blocks blocks," \
  "agreement $agreement"
