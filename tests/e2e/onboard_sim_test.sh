#!/usr/bin/env bash
# A shortened scripts/demo: semap-onboard on the simulated rig with --report, stopped by SIGTERM
# after 30 s, while planner-side semap-map-listeners join 8 s and 20 s late over DDS on
# loopback (a per-run domain, namespace and directory). Passes when:
# - the pose the robot published (odometry, received by the listener) is within 0.4 m RMSE of
#   the simulated truth (the report's truth.csv), computed here at equal stamps; raw GNSS
#   (0.5 m per axis) would give about 0.87 m;
# - SIGTERM ends the run cleanly: exit status 0, the map saved where map.save_path says;
# - summary.json holds the demo's figures within margins: >= 10 frames
#   mapped per second of drive, segmentation and map mIoU (the saved map's cells against the
#   simulated scene) above the thresholds below, no drops in the IMU and GNSS rings, plausible
#   latency and CPU; every figure read must be there (a missing one fails);
# - the report's files exist and load: semap-export reads map.smap (and exports it), the PNGs
#   are whole PNG files;
# - both late-joining listeners received the whole map: every block, and the same occupied
#   cells with the same classes as the map saved at SIGTERM (agreement);
# - the first map blocks are ready within 6 s of the process's start: the simulated receiver's
#   dual-antenna heading (rig.gnss_heading) makes the heading known at rest (1.9-2.5 s at load
#   5-7, up to 4 s at load 8-10); without it mapping waits until driving has shown it (~16 s);
# - the robot's own health figures hold: it initialised, perception turned the camera frames
#   into posed clouds and the map took (nearly) every one, the listener saw no rejected
#   blocks and plausible rt/semap/health reports.
set -euo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/stage_counts.sh"
onboard="$1" listener="$2" config="$3" xml="$4" exporter="$5"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
ns="e2e$$"
work=$(mktemp -d)
trap 'kill -9 ${pids:-} 2>/dev/null || true; rm -rf "$work"' EXIT
report="$work/report"
duration=30
fail() { echo "e2e: $*"; exit 1; }
# The run's own copy of the config: its map and namespace.
sed -e "s#save_path: .*#save_path: $work/map.smap#" -e "s#^dds:#dds:\n  namespace: $ns#" \
  "$config" >"$work/sim.yaml"
grep -q "namespace: $ns" "$work/sim.yaml" && grep -q "save_path: $work/map.smap" "$work/sim.yaml" ||
  fail "could not write the run's config"

# Thresholds per segmenter, measured on this 2-core machine (30 s runs, with margin; the
# rendered frames are deterministic, the poses nearly so):
# - palette on class-painted frames (a perfect segmenter): segmentation mIoU 1.000, map 0.769;
# - dnn (models/semap-seg.onnx on rendered frames): segmentation mIoU 0.832, map mIoU 0.701;
#   a retrained model needs these looked at again.
# map_miou scores every occupied cell against the world's class within its half-diagonal, so
# cells that the S-BKI kernel, depth noise and pose error put next to a surface count against it.
min_seg_palette=0.99 min_map_palette=0.65
min_seg_dnn=0.75 min_map_dnn=0.6

listen() { # listen DELAY NAME [flags]: a listener joining DELAY s after the robot started
  local delay="$1" name="$2"
  shift 2
  (
    sleep "$delay"
    exec "$listener" --domain "$domain" --ns "$ns" --seconds 90 --classes 8 \
      --save "$work/$name.pcd" "$@" >"$work/$name.log" 2>&1
  ) &
}
# The drive is longer than the run: SIGTERM ends it, as systemd or Ctrl-C would.
"$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" --report "$report" \
  >"$work/onboard.log" 2>&1 &
onboard_pid=$!
listen 8 received --health --odometry "$work/odometry.csv"
first_pid=$!
listen 20 late
late_pid=$!
pids="$onboard_pid $first_pid $late_pid"
sleep $((duration + 2))
kill -TERM "$onboard_pid"
status=0
wait "$onboard_pid" || status=$?
[[ $status -eq 0 ]] || { cat "$work/onboard.log"; fail "semap-onboard exited with $status on SIGTERM"; }
sleep 2 # the listeners take the robot's last blocks
kill -TERM "$first_pid" "$late_pid" 2>/dev/null || true
for pid in "$first_pid" "$late_pid"; do
  wait "$pid" || { cat "$work/received.log" "$work/late.log"; fail "a listener failed"; }
done
grep -q "map saved to $work/map.smap" "$work/onboard.log" || fail "no map saved at SIGTERM"

sed -n '/summary/,$p' "$work/onboard.log"
cat "$report/summary.json"
tail -3 "$work/received.log"
# A figure read from a file must be there: an empty or non-numeric one fails the test.
num() { [[ "$2" =~ ^-?[0-9]+([.][0-9]+)?(e-?[0-9]+)?$ ]] || fail "$1: '$2' is not a number"; }
at_least() { awk -v v="$1" -v m="$2" 'BEGIN { exit !(v != "" && v != "null" && v + 0 >= m + 0) }'; }
at_most() { awk -v v="$1" -v m="$2" 'BEGIN { exit !(v != "" && v != "null" && v + 0 <= m + 0) }'; }
json() { # json KEY: the number after "KEY": in summary.json (first match)
  grep -o "\"$1\": [-0-9.a-z]*" "$report/summary.json" | head -1 | sed 's/.*: //'
}

# The report's files.
for f in summary.json map.smap camera.png trajectory.png truth.csv; do
  [[ -s "$report/$f" ]] || fail "report has no $f"
done
cmp -s "$report/map.smap" "$work/map.smap" || fail "the report's map differs from map.save_path's"
"$exporter" "$work/map.smap" --png "$work/top.png" --variance-png "$work/variance.png" \
  --ply "$work/map.ply" --palette "$(dirname "$config")/sim-classes.yaml" --compare "$work/received.pcd" \
  >"$work/export.log" 2>&1 || { cat "$work/export.log"; fail "semap-export failed on map.smap"; }
"$exporter" "$work/map.smap" --compare "$work/late.pcd" >"$work/export-late.log" 2>&1 ||
  { cat "$work/export-late.log"; fail "semap-export --compare failed for the late listener"; }

# The published pose against the truth at the same IMU stamp, from 10 s after the first pose on
# (the filter's settling, as the report's own figure). Both are on the 5 ms IMU grid; the
# header's ROS time, taken back to CLOCK_MONOTONIC by the listener, may be off by microseconds.
pose_error=$(awk -F, 'function tick(s) { return int((s - t0) * 200 + 0.5) }
  NR == FNR { if (FNR == 2) t0 = $1; if (FNR > 1) truth[tick($1)] = $2 " " $3 " " $4; next }
  FNR > 1 && (tick($1) in truth) {
    if (first == "") first = $1
    if ($1 - first < 10) next
    split(truth[tick($1)], t, " ")
    sum += ($2 - t[1])^2 + ($3 - t[2])^2 + ($4 - t[3])^2; n++
  }
  END { if (n > 0) printf "%.3f %d\n", sqrt(sum / n), n }' "$report/truth.csv" "$work/odometry.csv")
published_rmse=${pose_error% *} published_n=${pose_error#* }
num "published pose RMSE" "$published_rmse"
at_least "$published_n" 100 || fail "only $published_n published poses matched the truth"
at_most "$published_rmse" 0.4 || fail "published pose RMSE $published_rmse m > 0.4 m"
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
  dnn) min_seg=$min_seg_dnn min_map=$min_map_dnn ;;
  *) fail "segmenter '$segmenter'" ;;
esac
rmse=$(json pose_rmse_m)
at_most "$rmse" 0.5 || fail "pose RMSE $rmse m > 0.5 m"
mapped=$(json frames_mapped) captured=$(json frames_captured)
# The camera runs at 15 Hz (the rig renders 13 to 15 frames a second on the 2-core test
# machine; fewer than 10 means it is starved); frames before the filter's heading settles are
# held and mapped at smoothed poses (map.hold_seconds), those the hold dropped count "without a
# pose", as do frames with no pose at all. Every frame rendered reaches perception, and every
# frame with a pose must reach the map (a few may be passed over).
unposed=$(sed -n 's/^perception *: .* \([0-9]*\) without a pose.*/\1/p' "$work/onboard.log")
# Frames posed while the filter's position sigma was above map.max_position_sigma_m (its first
# seconds) are not mapped either.
uncertain=$(sed -n 's/^perception *: .* \([0-9]*\) posed too uncertainly.*/\1/p' "$work/onboard.log")
unposed=$((unposed + ${uncertain:-0}))
taken=$(sed -n 's/^perception *: \([0-9]*\) frames,.*/\1/p' "$work/onboard.log")
at_least "$captured" $((10 * duration)) || fail "$captured frames captured in $duration s"
colour_drops=$(sed -n 's/^ring drops *: .*, colour \([0-9]*\),.*/\1/p' "$work/onboard.log")
[[ $((taken + colour_drops)) -eq "$captured" ]] ||
  fail "$captured frames rendered; perception took $taken, the colour ring dropped $colour_drops"
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
last=$(grep '^final: ' "$work/received.log" | tail -1)
blocks=$(awk '{print $3}' <<<"$last")
rejected=$(awk '{print $7}' <<<"$last")
robot_blocks=$(sed -n 's/^mapping *: .*, \([0-9]*\) blocks,.*/\1/p' "$work/onboard.log")
num "listener blocks" "$blocks"
num "listener rejected" "$rejected"
num "robot blocks" "$robot_blocks"
[[ $((blocks * 100)) -ge $((robot_blocks * 99)) && "$rejected" -eq 0 ]] ||
  fail "listener: $last; the robot's map has $robot_blocks blocks"
agreement=$(sed -n 's/^agreement //p' "$work/export.log")
at_least "$agreement" 0.99 || fail "received map vs saved map: $(tr '\n' ' ' <"$work/export.log")"
late_last=$(grep '^final: ' "$work/late.log" | tail -1)
late_blocks=$(awk '{print $3}' <<<"$late_last")
num "late listener blocks" "$late_blocks"
[[ $((late_blocks * 100)) -ge $((robot_blocks * 99)) ]] ||
  fail "late listener: $late_last; the robot's map has $robot_blocks blocks"
late_agreement=$(sed -n 's/^agreement //p' "$work/export-late.log")
at_least "$late_agreement" 0.99 ||
  fail "late listener's map vs saved map: $(tr '\n' ' ' <"$work/export-late.log")"

# The robot's health, as before the report existed.
grep -q "gated out), initialised=yes" "$work/onboard.log" || fail "not initialised"
first_blocks=$(sed -n 's/.*first map blocks .* (\([0-9.]*\) s after the process started).*/\1/p' \
  "$work/onboard.log")
num "first map blocks after the process started" "$first_blocks"
at_most "$first_blocks" 6 || fail "first map blocks $first_blocks s after the process started"
grep -q "^gnss heading *: [1-9][0-9]* applied" "$work/onboard.log" ||
  fail "no GNSS heading applied: $(grep '^gnss heading' "$work/onboard.log")"
# The costmap for nav2 went out, rebuilt around the robot as it drove and updated between.
costmap=$(grep '^costmap ' "$work/onboard.log" || true)
grids=$(awk '{print $3}' <<<"$costmap")
num "costmap grids" "$grids"
[[ "$grids" -ge 5 ]] || fail "costmap: '$costmap'"
check_stage_counts "$work/onboard.log"
num "frames mapped" "$mapped"
[[ "$mapped" -eq "$scans" ]] || fail "report: $mapped frames mapped, summary: $scans scans"
field() { # field LINE KIND NAME KEY: the value after "KIND NAME ... KEY" within that entry
  awk -v kind="$2" -v name="$3" -v key="$4" '{
    for (i = 1; i < NF; i++) if ($i == kind && $(i + 1) == name) {
      for (j = i + 2; j < NF && $j != "|"; j++) if ($j == key) { print $(j + 1); exit }
    } }' <<<"$1"
}
reports=$(grep -c '^health: ' "$work/received.log" || true)
[[ "$reports" -ge 3 ]] || fail "only $reports health reports"
health=$(grep '^health: ' "$work/received.log" | tail -1)
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
grep '^health: ' "$work/received.log" | awk '{ for (i = 1; i < NF; i++) if ($i == "mapping" && $(i + 2) > 0) ok = 1 }
  END { exit !ok }' || fail "mapping rate never > 0 in health"
num "gnss frames" "$gnss_frames"
num "gnss bad" "$gnss_bad"
[[ "$gnss_frames" -gt 0 && "$gnss_bad" -eq 0 ]] || fail "gnss driver health: $health"
awk -v r="$perc_rate" -v b="$perc_p99" 'BEGIN { exit !(r > 2 && b > 0 && b < 1000) }' ||
  fail "perception health implausible: $health"
# Ring drops in the health report are the rings' own counters: never more than at exit.
num "mapping drops" "$map_drops"
[[ "$map_drops" -le "$cloud_drops" ]] ||
  fail "mapping drops $map_drops vs cloud ring drops at exit '$cloud_drops'"
echo "e2e: last $health"
echo "e2e: $segmenter segmenter: published pose RMSE $published_rmse m ($published_n poses;" \
  "report $rmse m), segmentation mIoU $seg, map mIoU $map, $mapped frames mapped," \
  "latency p50 $p50 p99 $p99 ms, listeners $blocks / $late_blocks blocks, agreement" \
  "$agreement / $late_agreement"
