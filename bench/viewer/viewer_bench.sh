#!/usr/bin/env bash
# What the viewer costs semap-onboard on the simulated rig (issue 33's targets, docs/viewer.md):
#
# 1. CPU and frame-to-map latency, viewer off vs on, alternating (off, on, off, on, ...) in one go
#    so every figure sees the same machine load: config/sim.yaml (640x480 colour + Z16 depth at
#    15 Hz, the ONNX segmenter, DDS on loopback) for SECONDS each, `viewer.enabled: false`
#    against `true` with one node client (@foxglove/ws-protocol) subscribed to every channel and
#    reading. Per run: the process's CPU (the summary's "cpu" line over the whole run, and
#    /proc/PID/stat over the steady part, from 15 s, once mapping runs, to 2 s before the end),
#    the viewer's own threads ("viewer": the server, "viewer-img": the JPEGs; their
#    /proc/PID/task stat over the run; the stages' copies into its queue are not in it), the frames perception took (a loaded machine takes fewer, which moves the CPU), the
#    perception latency (frame -> cloud, summary) and the frame-to-map latency (the mapping
#    stage's p50/p99, as the health report carries it: --report's summary.json; with the viewer
#    on also the last health report the client got), the client's own CPU, /proc/loadavg.
#    Targets: CPU at most +0.1 core; latency unchanged within noise.
# 2. The map to a new client: the rig drives (rig.scenario MAP_SCENARIO, default loops of 50 m
#    radius as scripts/soak drives, at the camera's 15 Hz) with the viewer on until
#    /semap/map_cloud has MAP_POINTS (100000) occupied cells; then JOINS times a new client
#    connects, subscribes to /semap/map_cloud (latched) and times the whole cloud message from
#    its subscribe. Target: within 1 s for 100k occupied cells.
#
#   bench/viewer/viewer_bench.sh [BUILD_DIR] [SECONDS] [REPEATS] [JOINS]
#
# Defaults: build (scripts/build release: BUILD_DIR/bin/semap-onboard), 45 s, 2 alternations, 5
# joins. Environment: MAP_POINTS, MAP_SCENARIO (figure8 | loops), MAP_SPEED (m/s, default the
# config's 5), MAP_MAX_S (300: give up on the map part after this long). Node and the npm
# packages: scripts/setup, scripts/test-tools. Prints figures and the targets; no pass/fail.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-build}" seconds="${2:-45}" repeats="${3:-2}" joins="${4:-5}"
[[ "$build" == /* ]] || build="$root/$build"
onboard="$build/bin/semap-onboard"
map_points="${MAP_POINTS:-100000}" map_scenario="${MAP_SCENARIO:-loops}"
map_speed="${MAP_SPEED:-}" map_max_s="${MAP_MAX_S:-300}"
[[ -x "$onboard" ]] || { echo "viewer_bench: no $onboard (scripts/build release)" >&2; exit 2; }
command -v node >/dev/null || { echo "viewer_bench: no node (scripts/setup)" >&2; exit 2; }
((seconds >= 25)) || { echo "viewer_bench: SECONDS at least 25 (mapping starts ~15 s in)" >&2; exit 2; }
NODE_PATH=$("$root/scripts/test-tools")
export NODE_PATH
client="$root/bench/viewer/viewer_client.js"
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
export CYCLONEDDS_URI="file://$root/config/cyclonedds-loopback.xml"
domain=$(((RANDOM % 200) + 20))
ns="viewerbench$$"
ticks=$(getconf CLK_TCK)

# config/sim.yaml with its own map path and DDS namespace, the viewer section replaced.
# write_config OUT VIEWER_ENABLED [SCENARIO [SPEED]]
write_config() {
  awk -v save="$work/map.smap" -v ns="$ns" -v on="$2" -v scenario="${3:-}" -v speed="${4:-}" '
    /^viewer:/ { skipping = 1; next }
    skipping && /^[^ #]/ { skipping = 0 }
    skipping { next }
    /^ *save_path:/ { sub(/save_path: .*/, "save_path: " save) }
    scenario != "" && /^  scenario:/ { print "  scenario: " scenario; if (scenario == "loops") print "  loop_radius_m: 50"; next }
    speed != "" && /^  speed_m_s:/ { print "  speed_m_s: " speed; next }
    { print }
    /^dds:/ { print "  namespace: " ns }
    END { print "viewer:\n  enabled: " on "\n  address: 127.0.0.1\n  port: 0" }
  ' "$root/config/sim.yaml" >"$1"
  grep -q "namespace: $ns" "$1" && grep -q "^  enabled: $2" "$1" ||
    { echo "viewer_bench: could not write $1" >&2; exit 1; }
}
write_config "$work/off.yaml" false
write_config "$work/on.yaml" true

# The viewer's URL from the robot's log (port 0: the log line is the only place to learn it).
viewer_url() {
  local url=""
  for _ in $(seq 100); do
    url=$(grep -o 'viewer: http://[0-9.:]*/' "$1" | head -1 | sed 's/^viewer: http:/ws:/' || true)
    [[ -n "$url" ]] && { echo "$url"; return; }
    kill -0 "$2" 2>/dev/null || break
    sleep 0.2
  done
  cat "$1" >&2
  echo "viewer_bench: no 'viewer: http://...' line" >&2
  exit 1
}
proc_ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat" 2>/dev/null || echo ""; }
load() { cut -d' ' -f1-3 /proc/loadavg; }
jfield() { node -e 'const j = JSON.parse(require("fs").readFileSync(0, "utf8")); const v = eval("j." + process.argv[1]); console.log(v == null ? "-" : Array.isArray(v) ? v.join("/") : v)' "$1"; }

echo "semap-onboard: $onboard ($(stat -c %y "$onboard" | cut -d. -f1)), tree $(git -C "$root" rev-parse --short HEAD)"
echo "== 1. viewer off vs on: $seconds s of config/sim.yaml each, $repeats alternations =="
echo "   targets: CPU at most +0.1 core with the viewer on and one client; frame-to-map latency unchanged within noise"
printf "%-4s %3s %10s %12s %12s %6s %19s %19s %19s %14s %10s  %s\n" mode run "cpu_cores" "steady_cores" \
  "viewer_thr" frames "perception_p50/p99" "map_p50/p99(json)" "map_p50/p99(health)" "client_msgs/MB" \
  client_cpu "load start -> end"
for run in $(seq 1 "$repeats"); do
  for mode in off on; do
    rm -rf "$work"/map.smap* "$work/report" "$work/client.json"
    load0=$(load)
    (cd "$root" && exec "$onboard" --config "$work/$mode.yaml" --duration "$seconds" --domain "$domain" \
      --report "$work/report" >"$work/log" 2>&1) &
    pid=$!
    pids=("$pid")
    start=$(date +%s.%N)
    cpid=""
    if [[ "$mode" == on ]]; then
      url=$(viewer_url "$work/log" "$pid")
      node "$client" read --url "$url" >"$work/client.json" 2>"$work/client.err" &
      cpid=$!
      pids+=("$cpid")
    fi
    # /proc/PID/stat at 15 s and at SECONDS - 2 s after the start.
    t_a="" t_b="" s_a="" s_b="" vticks=0 vel=1
    while kill -0 "$pid" 2>/dev/null; do
      now=$(date +%s.%N)
      el=$(echo "$now - $start" | bc -l)
      # The viewer's own threads (server "viewer", JPEG encoder "viewer-img"), as far as they ran.
      if [[ "$mode" == on ]]; then
        v=$(cat /proc/"$pid"/task/*/stat 2>/dev/null | awk '$2 ~ /^\(viewer/ { t += $14 + $15 } END { print t + 0 }' || true)
        ((v > vticks)) && vticks=$v vel=$el
      fi
      if [[ -z "$t_a" ]] && (($(echo "$el >= 15" | bc))); then t_a=$(proc_ticks "$pid") s_a=$now; fi
      if [[ -z "$t_b" ]] && (($(echo "$el >= $seconds - 2" | bc))); then t_b=$(proc_ticks "$pid") s_b=$now; fi
      sleep 0.25
    done
    wait "$pid" || true
    if [[ -n "$cpid" ]]; then
      kill -TERM "$cpid" 2>/dev/null || true
      wait "$cpid" || true
    fi
    load1=$(load)
    steady="?"
    [[ -n "$t_a" && -n "$t_b" ]] && steady=$(echo "($t_b - $t_a) / $ticks / ($s_b - $s_a)" | bc -l | xargs printf "%.3f")
    cores=$(grep -o "^cpu  *: [0-9.]* cores" "$work/log" | grep -o "[0-9.]*" || echo "?")
    frames=$(grep -o "^perception  *: [0-9]* frames" "$work/log" | grep -o "[0-9]*" || echo "?")
    plat=$(sed -n 's/^perception .*latency p50 \([0-9.]*\) ms p99 \([0-9.]*\) ms.*/\1\/\2/p' "$work/log")
    mlat=$(jfield 'latency_frame_to_map_ms.p50 + "/" + j.latency_frame_to_map_ms.p99' <"$work/report/summary.json" 2>/dev/null || echo "?")
    hlat="-" cmsg="-" ccpu="-" vcores="-"
    [[ "$mode" == on ]] && vcores=$(echo "$vticks / $ticks / $vel" | bc -l | xargs printf "%.3f")
    if [[ "$mode" == on ]]; then
      if [[ -s "$work/client.json" ]]; then
        hlat=$(jfield health_mapping_p50_p99_ms <"$work/client.json" || echo "?")
        cmsg=$(jfield 'messages + "/" + j.megabytes' <"$work/client.json" || echo "?")
        ccpu=$(jfield client_cpu_cores <"$work/client.json" || echo "?")
      else
        hlat="client?" && cat "$work/client.err" >&2
      fi
    fi
    printf "%-4s %3d %10s %12s %12s %6s %19s %19s %19s %14s %10s  %s -> %s\n" "$mode" "$run" "$cores" "$steady" \
      "$vcores" "$frames" \
      "$plat" "$mlat" "$hlat" "$cmsg" "$ccpu" "$load0" "$load1"
    grep -E "^viewer " "$work/log" | sed 's/^/     /' || true
    [[ "$mode" == on && -s "$work/client.json" ]] &&
      echo "     client: $(jfield 'channels + " channels, per channel [messages, bytes]: " + JSON.stringify(j.per_channel)' <"$work/client.json")"
  done
done

echo "== 2. the map to a new client: rig.scenario $map_scenario${map_speed:+ at $map_speed m/s}, 15 Hz camera, until /semap/map_cloud has $map_points points; $joins new clients =="
echo "   target: the whole map within 1 s for 100k occupied cells"
write_config "$work/map.yaml" true "$map_scenario" "$map_speed"
rm -rf "$work"/map.smap*
load0=$(load)
(cd "$root" && exec "$onboard" --config "$work/map.yaml" --duration $((map_max_s + 60)) --domain "$domain" \
  >"$work/log" 2>&1) &
pid=$!
pids=("$pid")
start=$(date +%s)
url=$(viewer_url "$work/log" "$pid")
if node "$client" watch --url "$url" --points "$map_points" --max-seconds "$map_max_s" >"$work/watch.json"; then
  echo "   map cloud grew: $(grep -o '"t_s":[0-9]*,"map_cloud_points":[0-9]*' "$work/watch.json" | sed 's/"t_s"://; s/,"map_cloud_points":/ s: /' |
    awk 'NR % 5 == 1 { printf "%s, ", $0 } END { print $0 " points" }')"
  echo "   joining at $(($(date +%s) - start)) s of driving, load $(load)"
  node "$client" join --url "$url" --times "$joins" --pause 1.5 | tee "$work/join.json" | sed 's/^/   /'
  node -e '
    const lines = require("fs").readFileSync(process.argv[1], "utf8").trim().split("\n").map(JSON.parse);
    const ms = lines.map((l) => l.subscribe_to_message_ms).sort((x, y) => x - y);
    const pts = lines.map((l) => l.map_cloud_points);
    console.log("   subscribe -> whole map cloud: median " + ms[Math.floor(ms.length / 2)] + " ms, max " + ms[ms.length - 1] +
      " ms over " + ms.length + " new clients; " + Math.min(...pts) + "-" + Math.max(...pts) + " points, " +
      lines[0].megabytes + " MB; target 1000 ms")' "$work/join.json"
else
  tail -3 "$work/watch.json"
  echo "   the map did not reach $map_points points in $map_max_s s: no join measured"
fi
kill -TERM "$pid" 2>/dev/null || true
wait "$pid" || true
echo "   load start -> end: $load0 -> $(load)"
grep -E "^(cpu|perception|viewer) " "$work/log" | sed 's/^/   /' || true
