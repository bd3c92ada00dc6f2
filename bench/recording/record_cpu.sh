#!/usr/bin/env bash
# What recording costs semap-onboard on the simulated rig at its configured rates
# (config/sim.yaml: 640x480 colour + Z16 depth at 15 Hz, 200 Hz IMU, 10 Hz GNSS, DDS on loopback,
# the viewer off): runs without recording, with --record RUN.mcap (zstd, lz4) and, given the
# binary of the previous format, with --record DIR (the directory recorder), alternating, each
# REPEATS times for SECONDS, in one go so every figure sees the same machine load. Prints per run
# the process's CPU (user + system, cores over the run, from its summary), the frames the
# perception stage took (on a loaded machine it falls behind and takes fewer, which moves the
# process's CPU more than recording does), the recorder thread's own CPU (its /proc stat: the
# serialising, compressing and writing) and the recording's size.
#
#   bench/recording/record_cpu.sh build/bin/semap-onboard [OLD_SEMAP_ONBOARD] [SECONDS] [REPEATS]
set -euo pipefail
new="$1" old="${2:-}" seconds="${3:-30}" repeats="${4:-3}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export CYCLONEDDS_URI="file://$root/config/cyclonedds-loopback.xml"
domain=$(((RANDOM % 200) + 20))
# The simulated rig's config without the viewer section (the older binary does not know it).
awk -v save="$work/map.smap" '
  /^viewer:/ { skipping = 1; next }
  skipping && /^[^ #]/ { skipping = 0 }
  skipping { next }
  /^ *save_path:/ { sub(/save_path: .*/, "save_path: " save) }
  { print }' "$root/config/sim.yaml" >"$work/sim.yaml"
modes="none mcap-zstd mcap-lz4"
[[ -n "$old" ]] && modes="$modes dir none-old"
printf "%-10s %4s %8s %8s %9s %10s %s\n" mode run cores frames recorder "size_MB" "MB/s"
for run in $(seq 1 "$repeats"); do
  for mode in $modes; do
    exe="$new" args=()
    case "$mode" in
      mcap-zstd) args=(--record "$work/run.mcap") ;;
      mcap-lz4) args=(--record "$work/run.mcap" --record-compression lz4) ;;
      dir) exe="$old" args=(--record "$work/rec") ;;
      none-old) exe="$old" ;;
    esac
    rm -rf "$work/run.mcap" "$work/rec" "$work"/map.smap*
    (cd "$root" && exec "$exe" --config "$work/sim.yaml" --duration "$seconds" \
      --domain "$domain" "${args[@]}" >"$work/log" 2>&1) &
    pid=$!
    ticks=0
    while kill -0 "$pid" 2>/dev/null; do
      for task in /proc/"$pid"/task/*; do
        if [[ "$(cat "$task/comm" 2>/dev/null)" == recorder ]]; then
          t=$(awk '{ print $14 + $15 }' "$task/stat" 2>/dev/null || echo "$ticks")
          ticks=${t:-$ticks}
        fi
      done
      sleep 0.5
    done
    wait "$pid" || true
    recorder=$(echo "$ticks / $(getconf CLK_TCK) / $seconds" | bc -l)
    cores=$(grep -o "^cpu  *: [0-9.]* cores" "$work/log" | grep -o "[0-9.]*" || echo "?")
    frames=$(grep -o "^perception  *: [0-9]* frames" "$work/log" | grep -o "[0-9]*" || echo "?")
    size=0
    [[ -e "$work/run.mcap" ]] && size=$(stat -c %s "$work/run.mcap")
    [[ -d "$work/rec" ]] && size=$(du -sb "$work/rec" | cut -f1)
    printf "%-10s %4d %8s %8s %9.3f %10.1f %6.2f\n" "$mode" "$run" "$cores" "$frames" "$recorder" \
      "$(echo "$size / 1000000" | bc -l)" "$(echo "$size / 1000000 / $seconds" | bc -l)"
    grep "^recording " "$work/log" | sed 's/^/    /' || true
  done
done
