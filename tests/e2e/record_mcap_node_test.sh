#!/usr/bin/env bash
# semap-onboard --record RUN.mcap on the simulated rig with DDS on loopback, then @mcap/core
# (tests/viewer/mcap_read_test.js through viewer_test.sh: a reader no one here wrote) reads the
# recording: profile ros2, the summary's counts against the messages read through the index and
# streamed, every message decoded from its ros2msg schema, the file cut at 60 % still readable;
# and the channels hold the raw inputs and the outputs. Exits 77 (skipped) when node is missing.
set -euo pipefail
onboard="$1" config="$2" xml="$3"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
command -v node >/dev/null || { echo "record mcap node: SKIPPED: node is not installed"; exit 77; }
export CYCLONEDDS_URI="file://$xml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "record mcap node: FAIL: $*"
  exit 1
}
# A light run (320x240 at 5 Hz, palette segmenter) with DDS in its own domain and namespace,
# the viewer off.
domain=$(((RANDOM % 200) + 20))
awk -v save="$work/map.smap" -v ns="mcap$$" '
  /^viewer:/ { skipping = 1; print "viewer:\n  enabled: false"; next }
  skipping && /^[^ #]/ { skipping = 0 }
  skipping { next }
  /^ *save_path:/ { sub(/save_path: .*/, "save_path: " save) }
  /^dds:/ { print; print "  namespace: " ns; next }
  /^  width: 640/ { print "  width: 320"; next }
  /^  height: 480/ { print "  height: 240"; next }
  /^  fps: 15/ { print "  fps: 5"; next }
  /^  camera_image: rgb/ { print "  camera_image: classes"; next }
  /^  kind: onnx/ { print "  kind: palette"; next }
  /^  model_card:/ { next }
  { print }' "$config" >"$work/sim.yaml"
"$onboard" --config "$work/sim.yaml" --duration 20 --domain "$domain" \
  --record "$work/run.mcap" >"$work/run.log" 2>&1 || {
  tail -30 "$work/run.log"
  fail "semap-onboard failed"
}
grep "^recording " "$work/run.log"
"$here/../viewer/viewer_test.sh" mcap "$work/run.mcap" | tee "$work/node.log"
status=${PIPESTATUS[0]}
[[ $status -eq 0 ]] || exit "$status"
for channel in "/semap/raw/can (can_msgs/msg/Frame" "/semap/raw/gnss (semap_msgs/msg/GnssBytes" \
  "/semap/raw/colour/image (sensor_msgs/msg/Image" "/semap/raw/depth/image (sensor_msgs/msg/Image" \
  "/semap/recording/config (std_msgs/msg/String" "/semap/odometry (nav_msgs/msg/Odometry" \
  "/tf (tf2_msgs/msg/TFMessage" "/tf_static (tf2_msgs/msg/TFMessage" \
  "/semap/health (semap_msgs/msg/Health" "/semap/costmap (nav_msgs/msg/OccupancyGrid" \
  "/semap/map_cloud_updates (sensor_msgs/msg/PointCloud2"; do
  channel="${channel//mcap$$/}"
  grep -q -- "${channel%% *}.*${channel#* }" <(sed "s#/mcap$$##" "$work/node.log") ||
    fail "no channel $channel with messages"
done
echo "record mcap node: passed"
