#!/usr/bin/env bash
# The viewer's tests with clients no one here wrote (node and Debian's chromium; docs/viewer.md):
#   viewer_test.sh ws     ONBOARD CONFIG XML   @foxglove/ws-protocol client + a stalled client,
#                                              then the odometry against the simulated truth
#   viewer_test.sh page   ONBOARD CONFIG XML   chromium headless on the built-in page
#   viewer_test.sh mcap   FILE.mcap|WRITER...  @mcap/core reads an MCAP file semap wrote
#   viewer_test.sh record ONBOARD CONFIG XML   @mcap/core reads `semap-onboard --record RUN.mcap`
#                                              of 12 s on the simulated rig (SIGTERM)
# ws and page start semap-onboard on the simulated rig with a copy of CONFIG: its own map path,
# DDS domain and namespace, and `viewer:` on a free port (the port is read from the log line
# "viewer: http://127.0.0.1:PORT/"). Node packages: scripts/test-tools (a cache outside the
# repository). Exits 77 (skipped) only when node or chromium is not installed.
# SEMAP_DOCS_SCREENSHOT=docs/viewer-screenshot.png (page) also writes the docs' screenshot.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
mode="$1"
shift
fail() { echo "viewer test: FAIL: $*"; exit 1; }
skip() { echo "viewer test: SKIPPED: $*"; exit 77; }

command -v node >/dev/null || skip "node is not installed (the nodejs package: scripts/setup)"
chromium=$(command -v chromium || true)
[[ "$mode" != page || -n "$chromium" ]] || skip "chromium is not installed (scripts/setup)"
NODE_PATH=$("$root/scripts/test-tools") || fail "scripts/test-tools could not install the npm packages"
export NODE_PATH

work=$(mktemp -d)
onboard_pid=""
cleanup() {
  [[ -z "$onboard_pid" ]] || kill -9 "$onboard_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

if [[ "$mode" == mcap ]]; then
  if [[ "$1" == *.mcap ]]; then
    files=("$@")
  else # a program writing a sample: WRITER then one file per compression
    files=()
    for compression in zstd lz4 none; do
      "$1" "$work/sample-$compression.mcap" "$compression" || fail "$1 failed"
      files+=("$work/sample-$compression.mcap")
    done
  fi
  for f in "${files[@]}"; do
    node "$here/mcap_read_test.js" --file "$f" --min-messages 100 --truncate 1 || exit 1
  done
  exit 0
fi

onboard="$1" config="$2" xml="$3"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
ns="viewer$$"
# The run's own config: map path, namespace, and the viewer on any free port of loopback. No
# frames are held for the heading (map.hold_seconds 0): the held backlog, mapped in a burst as
# the heading settles, would raise the rates the stalled client's run is compared with.
awk -v save="$work/map.smap" -v ns="$ns" '
  /^viewer:/ { skipping = 1; next }
  skipping && /^[^ #]/ { skipping = 0 }
  skipping { next }
  /^ *save_path:/ { sub(/save_path: .*/, "save_path: " save "\n  hold_seconds: 0") }
  { print }
  /^dds:/ { print "  namespace: " ns }
  END { print "viewer:\n  enabled: true\n  address: 127.0.0.1\n  port: 0\n  client_budget_bytes: 262144" }
' "$config" >"$work/sim.yaml"
grep -q "namespace: $ns" "$work/sim.yaml" || fail "could not write the run's config"

report_args=()
[[ "$mode" == ws ]] && report_args=(--report "$work/report")
if [[ "$mode" == record ]]; then
  cd "$root"
  "$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" --record "$work/run.mcap" \
    >"$work/onboard.log" 2>&1 &
  onboard_pid=$!
  sleep 12 # SIGTERM ends the run as systemd would: exit 0, the file closed with its summary
  kill -TERM "$onboard_pid"
  status=0
  wait "$onboard_pid" || status=$?
  onboard_pid=""
  [[ $status -eq 0 ]] || { tail -30 "$work/onboard.log"; fail "semap-onboard --record exited with $status"; }
  grep -E '^recording' "$work/onboard.log" || true
  [[ -f "$work/run.mcap" ]] || fail "no $work/run.mcap"
  node "$here/mcap_read_test.js" --file "$work/run.mcap" --min-messages 1000 --truncate 1 \
    --topics /semap/odometry,/semap/health,/semap/raw/can
  exit
fi
cd "$root"
"$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" "${report_args[@]}" \
  >"$work/onboard.log" 2>&1 &
onboard_pid=$!
url=""
for _ in $(seq 100); do
  url=$(grep -o 'viewer: http://[0-9.:]*/' "$work/onboard.log" | head -1 | sed 's/^viewer: //' || true)
  [[ -n "$url" ]] && break
  kill -0 "$onboard_pid" 2>/dev/null || { cat "$work/onboard.log"; fail "semap-onboard exited"; }
  sleep 0.2
done
[[ -n "$url" ]] || { cat "$work/onboard.log"; fail "no 'viewer: http://...' line in 20 s"; }
echo "viewer test: robot at $url (domain $domain, namespace $ns)"

stop_robot() {
  kill -TERM "$onboard_pid"
  local status=0
  wait "$onboard_pid" || status=$?
  onboard_pid=""
  [[ $status -eq 0 ]] || { tail -40 "$work/onboard.log"; fail "semap-onboard exited with $status on SIGTERM"; }
}

case "$mode" in
  ws)
    # The costmap's configured size in cells.
    cm() { sed -n '/^costmap:/,/^[^ ]/p' "$config" | sed -n "s/^ *$1: *\([0-9.]*\).*/\1/p" | head -1; }
    res=$(cm resolution) width=$(cm width_m) height=$(cm height_m)
    cells=$(awk -v w="$width" -v h="$height" -v r="$res" 'BEGIN { printf "%dx%d", w / r + 0.5, h / r + 0.5 }')
    status=0
    node "$here/ws_client_test.js" --url "${url/http:/ws:}" --baseline 6 --stall 10 --max-seconds 60 \
      --costmap "$cells" --costmap-resolution "$res" --out "$work" || status=$?
    stop_robot
    sed -n '/summary/,$p' "$work/onboard.log" | grep -iE 'viewer|pose vs truth' || true
    [[ $status -eq 0 ]] || { tail -30 "$work/onboard.log"; exit 1; }
    [[ -s "$work/report/truth.csv" ]] || fail "the report has no truth.csv"
    node "$here/truth.js" "$work/odometry.csv" "$work/report/truth.csv" 0.5
    ;;
  page)
    status=0
    extra=()
    [[ -z "${SEMAP_DOCS_SCREENSHOT:-}" ]] || extra=(--docs-screenshot "$SEMAP_DOCS_SCREENSHOT")
    node "$here/page_test.js" --url "$url" --chromium "$chromium" --out "${SEMAP_VIEWER_OUT:-$work}" \
      --palette "$root/$(sed -n "s/^ *palette: *\([^ ]*\).*/\1/p" "$config" | head -1)" "${extra[@]}" || status=$?
    stop_robot
    [[ $status -eq 0 ]] || { tail -30 "$work/onboard.log"; exit 1; }
    ;;
  *) fail "unknown mode $mode" ;;
esac
