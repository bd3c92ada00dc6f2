#!/usr/bin/env bash
# Runs inside the fresh Debian 12 machine that scripts/deb-vm boots, as a oneshot systemd unit,
# after apt installed the package: points /etc/semap/semap.yaml at the simulated rig, and has
# systemd run semap-onboard.service: started (READY=1), alive on the watchdog, restarted after a
# hang (watchdog) and after a crash (Restart=on-failure), checkpointing, and stopped with a saved
# map. Prints `VM: ...` lines and one `VM-RESULT pass|fail ...` on the serial console, then
# powers the machine off.
exec >/dev/ttyS0 2>&1
set -u
started=$(date +%s)
say() { echo "VM: [$(($(date +%s) - started)) s] $*"; }
finish() {
  echo "VM-RESULT $*"
  systemctl poweroff --no-block
  exit 0
}
fail() {
  say "journal of semap-onboard.service:"
  journalctl -u semap-onboard.service --no-pager -o short-monotonic | tail -40
  finish "fail: $*"
}
prop() { systemctl show -P "$1" semap-onboard.service; }
restarted() { (($(prop NRestarts) >= $1)); }
active() { [[ "$(prop ActiveState)" == active ]]; }
# wait_for SECONDS COMMAND...: true once the command is (run anew each second), false after.
wait_for() {
  local until=$(($(date +%s) + $1))
  shift
  until "$@"; do
    (($(date +%s) < until)) || return 1
    sleep 1
  done
}

. /etc/os-release
say "$PRETTY_NAME, kernel $(uname -r), $(systemctl --version | head -1), $(nproc) cpus," \
  "$(free -m | awk '/^Mem:/ {print $2}') MiB, no network: $(ip -o link 2>/dev/null | grep -vc ' lo:') links"

# --- installed by scripts/deb-vm (apt-get install ./semap_*.deb in this root, before boot) ----
dpkg -s semap | grep -q '^Status: install ok installed' || fail "dpkg does not list semap"
semap-onboard --help >/dev/null || fail "semap-onboard --help"
[[ "$(prop UnitFileState)" == disabled || "$(prop UnitFileState)" == enabled ]] ||
  fail "systemd does not know semap-onboard.service: $(prop LoadState)"

# --- the robot's configuration: the simulated rig, its map in the service's state directory ----
# Under software emulation (no KVM) float code runs some hundred times slower than on the host:
# a 640x480 frame takes ~12 s to render and the network ~13 s per frame, so a frame reaches the
# map 20-40 s after its stamp, beyond the 10 s of poses the filter keeps by default. Here: a
# 320x240 camera (the network's own input size) at 2 Hz and 150 s of poses.
sed -e 's#^  save_path: .*#  save_path: /var/lib/semap/map.smap\n  resume: true#' \
  -e 's#^  baud: 115200#  baud: 115200\n  realtime_priority: 40#' \
  -e 's#^  width: 640#  width: 320#' -e 's#^  height: 480#  height: 240#' -e 's#^  fps: 15#  fps: 2#' \
  -e 's#^estimator:#estimator:\n  history: 30000#' \
  -e 's#^  config: config/cyclonedds-loopback.xml#  config: /etc/semap/cyclonedds.xml#' \
  /usr/share/semap/config/sim.yaml >/etc/semap/semap.yaml
grep -q '^  save_path: /var/lib/semap/map.smap' /etc/semap/semap.yaml || fail "config edit"
grep -q '^  width: 320' /etc/semap/semap.yaml || fail "config edit: camera width"
grep -q '^  history: 30000' /etc/semap/semap.yaml || fail "config edit: pose history"

# --- start: Type=notify, so start returns once the pipeline said READY=1 ----------------------
t0=$(date +%s)
systemctl start semap-onboard.service || fail "systemctl start"
say "started (READY=1) in $(($(date +%s) - t0)) s, main pid $(prop MainPID)," \
  "watchdog $(prop WatchdogUSec)"
[[ "$(prop WatchdogUSec)" != 0 ]] || fail "no watchdog"
# The GNSS driver's thread (gnss.realtime_priority: 40) at SCHED_FIFO, the others not.
fifo=$(ps -L -o cls=,rtprio= -p "$(prop MainPID)" | awk '$1 == "FF" {print $2}' | sort | uniq -c)
[[ "$(echo $fifo)" == "1 40" ]] || fail "threads at SCHED_FIFO (count, priority): ${fifo:-none}"
say "the GNSS driver thread runs at SCHED_FIFO 40, the other" \
  "$(($(ps -L -o cls= -p "$(prop MainPID)" | grep -c .) - 1)) threads at normal scheduling"
sleep 25
[[ "$(prop ActiveState)" == active ]] || fail "not active 25 s after start: $(prop ActiveState)"
[[ "$(prop NRestarts)" == 0 ]] || fail "restarted $(prop NRestarts) times without a fault"
journalctl -u semap-onboard.service --no-pager | grep -q "systemd watchdog: pinging" ||
  fail "the service does not ping the watchdog"
wait_for 60 test -s /var/lib/semap/map.smap.log || fail "no checkpoint in /var/lib/semap"
# The log starts with its header; it grows when a checkpoint holds mapped blocks.
header=$(stat -c %s /var/lib/semap/map.smap.log)
grown() { (($(stat -c %s /var/lib/semap/map.smap.log) > header)); }
wait_for 300 grown || fail "no mapped blocks in the checkpoint 300 s after start"
say "running: checkpoint $(stat -c %s /var/lib/semap/map.smap.log) bytes"

# --- a hung pipeline: the watchdog (WatchdogSec=10) kills it and systemd restarts it ----------
pid=$(prop MainPID)
kill -STOP "$pid"
t0=$(date +%s)
wait_for 60 restarted 1 || fail "a stopped process was not restarted"
journalctl -u semap-onboard.service --no-pager | grep -q "Watchdog timeout" ||
  fail "restarted, but not by the watchdog"
wait_for 120 active || fail "not active after the watchdog restart"
say "hung pid $pid: watchdog restart after $(($(date +%s) - t0)) s, new pid $(prop MainPID)"
resumed=$(journalctl -u semap-onboard.service --no-pager -o cat -g "map resumed from" | tail -1)
blocks=$(sed -n 's/.*: \([0-9]*\) blocks of.*/\1/p' <<<"$resumed")
((${blocks:-0} > 0)) || fail "the restarted service did not resume its map: $resumed"
say "the restarted service $resumed"

# --- a crash: Restart=on-failure --------------------------------------------------------------
sleep 5
pid=$(prop MainPID)
kill -SEGV "$pid"
wait_for 60 restarted 2 || fail "a crashed process was not restarted"
wait_for 120 active || fail "not active after the crash restart"
say "crashed pid $pid (SIGSEGV): restarted as pid $(prop MainPID)"

# --- stop: SIGTERM stops the stages and saves the map ---------------------------------------
sleep 15
t0=$(date +%s)
systemctl stop semap-onboard.service || fail "systemctl stop"
[[ "$(prop Result)" == success ]] || fail "stop result: $(prop Result)"
journalctl -u semap-onboard.service --no-pager | grep -q "map saved to /var/lib/semap/map.smap" ||
  fail "no map saved at stop"
semap-export /var/lib/semap/map.smap --ply /root/map.ply >/root/export.log 2>&1 ||
  { cat /root/export.log; fail "semap-export cannot read the saved map"; }
cells=$(sed -n 's/^element vertex //p' /root/map.ply)
((cells > 1000)) || fail "the saved map has $cells occupied cells"
say "stopped in $(($(date +%s) - t0)) s: map $(stat -c %s /var/lib/semap/map.smap) bytes," \
  "$cells occupied cells"
finish "pass: installed, started, watchdog and crash restarts, map saved at stop"
