#!/usr/bin/env bash
# semap-onboard on the simulated rig for 20 s while semap-map-listener follows the map over
# DDS on loopback. Passes when the robot initialised, its pose stayed within 1 m of the
# simulated truth, its perception stage turned the rig's camera frames into posed clouds and
# the map took (nearly) every one of them, and the listener received blocks with no
# rejections, and the map it saved at exit exports to a top-down PNG. The listener also prints
# the robot's rt/semap/health reports, which must carry plausible figures.
set -euo pipefail
onboard="$1" listener="$2" config="$3" xml="$4" exporter="$5"
export CYCLONEDDS_URI="file://$xml"
domain=$(( (RANDOM % 200) + 20 ))
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The listener runs as long as the robot (20 s plus start-up) to see its health reports.
"$listener" --domain "$domain" --seconds 24 --classes 8 --health \
  --save "$work/received.pcd" >"$work/listener.log" 2>&1 &
listener_pid=$!
rm -f build/sim_map.smap
"$onboard" --config "$config" --duration 20 --domain "$domain" >"$work/onboard.log" 2>&1 || {
  echo "semap-onboard failed"; cat "$work/onboard.log"; exit 1; }
wait "$listener_pid" || { echo "listener failed"; cat "$work/listener.log"; exit 1; }

cat "$work/onboard.log" | sed -n '/summary/,$p'
tail -3 "$work/listener.log"
rmse=$(sed -n 's/.*position RMSE \([0-9.]*\) m.*/\1/p' "$work/onboard.log")
[[ -n "$rmse" ]] || { echo "no accuracy line"; exit 1; }
awk -v r="$rmse" 'BEGIN { exit !(r < 1.0) }' || { echo "pose RMSE $rmse m >= 1 m"; exit 1; }
grep -q "gated out), initialised=yes" "$work/onboard.log" || { echo "not initialised"; exit 1; }
scans=$(sed -n 's/^mapping *: \([0-9]*\) scans.*/\1/p' "$work/onboard.log")
posed=$(sed -n 's/^perception *: [0-9]* frames, \([0-9]*\) clouds mapped.*/\1/p' "$work/onboard.log")
frames=$(sed -n 's/^perception *: \([0-9]*\) frames.*/\1/p' "$work/onboard.log")
# The rig renders at 5 Hz for 20 s; the first frames come before the filter initialises.
[[ -n "$posed" && -n "$frames" && "$frames" -ge 90 && $(( posed * 10 )) -ge $(( frames * 7 )) ]] || {
  echo "perception: $frames frames, $posed clouds"; exit 1; }
# The cloud ring drops the oldest scan rather than stall perception; allow a few drops.
[[ "$scans" -gt 50 && $(( scans * 10 )) -ge $(( posed * 9 )) ]] || {
  echo "scans $scans, posed $posed"; exit 1; }
last=$(grep '^final: ' "$work/listener.log" | tail -1)
blocks=$(awk '{print $3}' <<<"$last")
rejected=$(awk '{print $7}' <<<"$last")
[[ "$blocks" -ge 2000 && "$rejected" -eq 0 ]] || { echo "listener: $last"; exit 1; }
[[ -s "$work/received.pcd" ]] || { echo "listener saved no map"; exit 1; }
"$exporter" build/sim_map.smap --png "$work/top.png" --ply "$work/map.ply" >"$work/export.log" 2>&1 || {
  echo "semap-export failed on the saved map"; cat "$work/export.log"; exit 1; }
[[ -s "$work/top.png" && -s "$work/map.ply" ]] || { echo "export wrote nothing"; exit 1; }
# Health at 1 Hz: "health: stage <name> rate R depth D drops N p50 X p99 Y | ... | driver ..".
field() {  # field LINE KIND NAME KEY: the value after "KIND NAME ... KEY" within that entry
  awk -v kind="$2" -v name="$3" -v key="$4" '{
    for (i = 1; i < NF; i++) if ($i == kind && $(i + 1) == name) {
      for (j = i + 2; j < NF && $j != "|"; j++) if ($j == key) { print $(j + 1); exit }
    } }' <<<"$1"
}
reports=$(grep -c '^health: ' "$work/listener.log" || true)
[[ "$reports" -ge 3 ]] || { echo "only $reports health reports"; exit 1; }
health=$(grep '^health: ' "$work/listener.log" | tail -1)
est_rate=$(field "$health" stage estimation rate)
est_p50=$(field "$health" stage estimation p50)
est_p99=$(field "$health" stage estimation p99)
map_drops=$(field "$health" stage mapping drops)
perc_rate=$(field "$health" stage perception rate)
perc_p99=$(field "$health" stage perception p99)
gnss_frames=$(field "$health" driver gnss frames)
gnss_bad=$(field "$health" driver gnss bad)
awk -v r="$est_rate" -v a="$est_p50" -v b="$est_p99" 'BEGIN { exit !(r > 50 && b >= a && b < 1000) }' || {
  echo "estimation health implausible: $health"; exit 1; }
grep '^health: ' "$work/listener.log" | awk '{ for (i = 1; i < NF; i++) if ($i == "mapping" && $(i + 2) > 0) ok = 1 }
  END { exit !ok }' || { echo "mapping rate never > 0 in health"; grep '^health: ' "$work/listener.log"; exit 1; }
[[ "$gnss_frames" -gt 0 && "$gnss_bad" -eq 0 ]] || { echo "gnss driver health: $health"; exit 1; }
awk -v r="$perc_rate" -v b="$perc_p99" 'BEGIN { exit !(r > 2 && b > 0 && b < 1000) }' || {
  echo "perception health implausible: $health"; exit 1; }
# Ring drops in the health report are the rings' own counters: never more than at exit.
cloud_drops=$(sed -n 's/^ring drops .* clouds \([0-9]*\)$/\1/p' "$work/onboard.log")
[[ -n "$map_drops" && -n "$cloud_drops" && "$map_drops" -le "$cloud_drops" ]] || {
  echo "mapping drops $map_drops vs cloud ring drops at exit '$cloud_drops'"; exit 1; }
echo "e2e: last $health"
echo "e2e: health ${reports} reports, estimation ${est_rate} Hz p50 ${est_p50} ms p99 ${est_p99} ms"
echo "e2e: rmse ${rmse} m, ${scans} scans, listener ${blocks} blocks"
