#!/usr/bin/env bash
# The whole robot on arm64, EMULATED: the aarch64 semap-onboard (scripts/cross-arm64's build, or
# the files of the arm64 .deb) runs under qemu-user on this x86-64 host, on the simulated rig for
# 20 s of drive, while the host's own x86-64 semap-map-listener follows its map over Cyclone DDS
# on loopback (config/cyclonedds-loopback.xml: 127.0.0.1 only, multicast off, unicast peer
# 127.0.0.1; a per-run domain and namespace). Passes when:
# - the programs are what they claim: the robot an aarch64 ELF, the listener the host's;
# - the arm64 robot ran by itself to the end of its drive and exited 0 (after --duration it exits
#   1 when its filter never initialised or its camera mapped nothing), with every colour frame
#   and cloud accounted for (stage_counts.sh), and saved its map;
# - the listener received every block of that map and rejected none;
# - the map the arm64 robot saved, read on the host by semap-export, and the map the listener
#   received have the same occupied cells with the same classes (semap-export --compare, as
#   e2e_onboard_sim compares them): as many cells in each, all of them the same (agreement 1).
# Emulated floating point is much slower than the host's, so the robot's camera runs at 320x240
# and 2 Hz and its filter keeps 150 s of poses (estimator.history), as in deb_vm_check.sh; and it
# maps once the filter's heading sigma is below 10 degrees (3 in sim.yaml: reached only 15 s
# into the 20 s drive), so that more than the last few frames reach the map.
#
#   arm64_robot_test.sh --onboard BIN --data DIR --sysroot DIR --listener BIN --export BIN
#                       --cyclonedds XML [--seconds S] [--toolchain-root DIR] [--keep DIR]
#
# --data: the folder with config/ and models/ the robot runs in (the checkout, or usr/share/semap
# of the unpacked package); --sysroot: scripts/cross-arm64's arm64 libraries; --keep: copy the
# logs, config, saved and received maps there.
set -euo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/stage_counts.sh"
seconds=20 toolchain=/usr/aarch64-linux-gnu keep=""
onboard="" data="" sysroot="" listener="" exporter="" xml=""
while (($#)); do
  case "$1" in
    --onboard) onboard="$(realpath "$2")"; shift 2 ;;
    --data) data="$(realpath "$2")"; shift 2 ;;
    --sysroot) sysroot="$(realpath "$2")"; shift 2 ;;
    --listener) listener="$(realpath "$2")"; shift 2 ;;
    --export) exporter="$(realpath "$2")"; shift 2 ;;
    --cyclonedds) xml="$(realpath "$2")"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --toolchain-root) toolchain="$2"; shift 2 ;;
    --keep) keep="$(realpath -m "$2")"; shift 2 ;;
    *) echo "arm64: unknown argument $1" >&2; exit 2 ;;
  esac
done
for a in onboard data sysroot listener exporter xml; do
  [[ -n "${!a}" && -e "${!a}" ]] || { echo "arm64: --${a} missing or not found" >&2; exit 2; }
done
work=$(mktemp -d)
pids=""
finish() {
  local status=$?
  kill -9 $pids 2>/dev/null || true
  if [[ -n "$keep" ]]; then
    mkdir -p "$keep"
    cp -r "$work"/. "$keep"/
  fi
  rm -rf "$work"
  return $status
}
trap finish EXIT
fail() { echo "arm64: $*"; exit 1; }
num() { [[ "$2" =~ ^-?[0-9]+([.][0-9]+)?$ ]] || fail "$1: '$2' is not a number"; }

# --- the programs -------------------------------------------------------------------------
command -v qemu-aarch64 >/dev/null || fail "no qemu-aarch64 (apt-get install qemu-user)"
command -v file >/dev/null || fail "no file(1)"
file -L "$onboard" | grep -q 'ELF 64-bit LSB .*ARM aarch64' || fail "not aarch64: $(file -L "$onboard")"
host_elf=$(file -L "$listener")
[[ "$host_elf" == *"ELF 64-bit LSB"* && "$host_elf" != *aarch64* ]] ||
  fail "the listener is not a host program: $host_elf"
libpath="${sysroot}/usr/lib/aarch64-linux-gnu:${sysroot}/lib/aarch64-linux-gnu:${sysroot}/usr/lib"
# -L: the ELF interpreter and libc from the cross toolchain; -E: the sysroot's libraries for the
# emulated program only (not for qemu itself).
emulate=(qemu-aarch64 -L "$toolchain" -E LD_LIBRARY_PATH="$libpath")

# --- the robot's configuration: the simulated rig, slowed down for emulation ----------------
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
ns="arm64e2e$$"
sed -e "s#^  save_path: .*#  save_path: $work/map.smap#" -e "s#^dds:#dds:\n  namespace: $ns#" \
  -e "s#^  config: config/cyclonedds-loopback.xml#  config: $xml#" \
  -e 's#^  width: 640#  width: 320#' -e 's#^  height: 480#  height: 240#' -e 's#^  fps: 15#  fps: 2#' \
  -e 's#^estimator:#estimator:\n  history: 30000#' \
  -e 's#^  start_heading_sigma_deg: [0-9.]* #  start_heading_sigma_deg: 10 #' \
  "$data/config/sim.yaml" >"$work/robot.yaml"
for edit in "save_path: $work/map.smap" "namespace: $ns" "config: $xml" "width: 320" "fps: 2" \
  "history: 30000" "start_heading_sigma_deg: 10"; do
  grep -Eq "^  ${edit}( |\$)" "$work/robot.yaml" || fail "config edit: $edit"
done

# --- run: the listener (x86-64) first, then the robot (aarch64 under qemu-user) -------------
"$listener" --domain "$domain" --ns "$ns" --classes 8 --save "$work/received.pcd" \
  >"$work/listener.log" 2>&1 &
listener_pid=$!
pids="$listener_pid"
t0=$(date +%s.%N)
status=0
(cd "$data" && exec timeout -s KILL 900 "${emulate[@]}" "$onboard" --config "$work/robot.yaml" \
  --duration "$seconds" --domain "$domain") >"$work/onboard.log" 2>&1 || status=$?
robot_s=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
[[ $status -eq 0 ]] || { tail -40 "$work/onboard.log"; fail "the arm64 semap-onboard exited $status"; }
grep -q "map saved to $work/map.smap" "$work/onboard.log" || fail "no map saved"
sed -n '/summary/,$p' "$work/onboard.log"
check_stage_counts "$work/onboard.log"
robot_blocks=$(sed -n 's/^mapping *: .*, \([0-9]*\) blocks,.*/\1/p' "$work/onboard.log")
num "robot blocks" "$robot_blocks"
((scans > 0 && robot_blocks > 0)) || fail "the robot mapped $scans scans into $robot_blocks blocks"

# The listener has the robot's last blocks (the robot sent them as it stopped): wait for its
# count to reach the robot's, then stop it; it saves what it received.
received_blocks() { sed -n 's/^blocks \([0-9]*\) .*/\1/p' "$work/listener.log" | tail -1; }
for _ in $(seq 60); do
  [[ "$(received_blocks)" == "$robot_blocks" ]] && break
  sleep 1
done
kill -TERM "$listener_pid"
wait "$listener_pid" || { cat "$work/listener.log"; fail "the listener failed"; }
last=$(grep '^final: ' "$work/listener.log" | tail -1)
blocks=$(awk '{print $3}' <<<"$last") rejected=$(awk '{print $7}' <<<"$last")
num "listener blocks" "$blocks"
num "listener rejected" "$rejected"
[[ "$blocks" -eq "$robot_blocks" && "$rejected" -eq 0 ]] ||
  fail "listener: $last; the arm64 robot's map has $robot_blocks blocks"

# --- the saved map against the received one, compared on the host ---------------------------
"$exporter" "$work/map.smap" --compare "$work/received.pcd" >"$work/compare.log" 2>&1 ||
  { cat "$work/compare.log"; fail "semap-export cannot read the arm64 robot's map"; }
value() { sed -n "s/^$1 //p" "$work/compare.log"; }
saved=$(value occupied_cells) received=$(value received_cells) same=$(value same_cells)
agreement=$(value agreement)
for figure in saved received same agreement; do num "$figure" "${!figure}"; done
((saved > 0)) || fail "the saved map has no occupied cells"
[[ "$saved" -eq "$received" && "$same" -eq "$saved" ]] ||
  fail "saved map $saved occupied cells, received $received, $same the same (agreement $agreement)"
echo "arm64: robot aarch64 under qemu-user for ${robot_s} s (drive ${seconds} s): $frames frames," \
  "$scans mapped, $robot_blocks blocks, $saved occupied cells saved; listener x86-64:" \
  "$blocks blocks, $received occupied cells received, $same the same (agreement $agreement)"
