#!/usr/bin/env bash
# The Debian package as a robot gets it: CPack builds semap_<version>_<arch>.deb from this build;
# its runtime dependencies (dpkg-shlibdeps) resolve against Debian's archive (apt-get
# --simulate); its /etc/semap files are conffiles; unpacked into a scratch root, the installed
# semap-onboard answers --help and runs the simulated rig from the installed data only
# (/usr/share/semap as its working directory, as the service runs), telling a stand-in for
# systemd's notify socket READY=1, a WATCHDOG=1 a second and STOPPING=1 (with the pings that go
# on while it stops), and saving its map.
set -euo pipefail
build="$1"
work=$(mktemp -d)
trap 'kill -9 ${pids:-} 2>/dev/null || true; rm -rf "$work"' EXIT
fail() { echo "deb: $*"; exit 1; }

(cd "$build" && cpack -G DEB -B "$work/out" >"$work/cpack.log" 2>&1) ||
  { cat "$work/cpack.log"; fail "cpack failed"; }
deb=$(ls "$work"/out/semap_*_*.deb)
echo "deb: $(basename "$deb"), $(du -h "$deb" | cut -f1)"
depends=$(dpkg-deb -f "$deb" Depends)
for lib in libopencv-core libddsc libyaml-cpp libtbb libturbojpeg libsocketcan libspdlog; do
  grep -q "$lib" <<<"$depends" || fail "Depends lacks $lib: $depends"
done
[[ "$(dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles)" == $'/etc/semap/semap.yaml\n/etc/semap/cyclonedds.xml' ]] ||
  fail "conffiles: $(dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles)"
# Every dependency is a package Debian has (installed here or not).
apt-get install --simulate --no-install-recommends "$deb" >"$work/apt.log" 2>&1 ||
  { cat "$work/apt.log"; fail "apt-get cannot install the package"; }

root="$work/root"
dpkg-deb -x "$deb" "$root"
for f in usr/bin/semap-onboard usr/bin/semap-map-listener usr/bin/semap-segment \
  usr/share/semap/models/semap-seg.onnx usr/share/semap/models/enet-cityscapes.net \
  usr/share/semap/models/enet-cityscapes.yaml usr/share/semap/models/enet-cityscapes.LICENSE \
  usr/share/semap/config/sim.yaml usr/share/semap/imu.dbc etc/semap/semap.yaml \
  usr/lib/systemd/system/semap-onboard.service usr/share/doc/semap/deploy.md; do
  [[ -e "$root/$f" ]] || fail "the package has no /$f"
done
if command -v systemd-analyze >/dev/null; then
  # The unit as systemd reads it, its ExecStart pointed at the unpacked binary.
  sed "s#/usr/bin/semap-onboard#$root/usr/bin/semap-onboard#" \
    "$root/usr/lib/systemd/system/semap-onboard.service" >"$work/semap-onboard.service"
  systemd-analyze verify "$work/semap-onboard.service" >"$work/verify.log" 2>&1 ||
    { cat "$work/verify.log"; fail "systemd-analyze verify"; }
fi
onboard="$root/usr/bin/semap-onboard"
"$onboard" --help >"$work/help.log" || fail "semap-onboard --help"
grep -q -- "--record" "$work/help.log" || fail "--help: $(head -3 "$work/help.log")"

# systemd's notify socket, stood in for by a datagram socket that keeps what it hears.
/usr/bin/python3 - "$work/notify.sock" "$work/notify.log" <<'PY' &
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
with open(sys.argv[2], "w") as log:
    while True:
        log.write(s.recv(4096).decode() + "\n")
        log.flush()
PY
pids=$!
for _ in $(seq 50); do [[ -S "$work/notify.sock" ]] && break; sleep 0.1; done
export CYCLONEDDS_URI="file://$root/usr/share/semap/config/cyclonedds-loopback.xml"
domain=$(((RANDOM % 200) + 20))
(cd "$root/usr/share/semap" &&
  NOTIFY_SOCKET="$work/notify.sock" WATCHDOG_USEC=10000000 \
    "$onboard" --config config/sim.yaml --duration 20 --domain "$domain" --save "$work/map.smap" \
    >"$work/onboard.log" 2>&1) || { cat "$work/onboard.log"; fail "the installed semap-onboard failed"; }
sleep 0.5
grep -q "perception: dnn segmenter" "$work/onboard.log" ||
  { cat "$work/onboard.log"; fail "the installed model did not load"; }
grep -q "systemd watchdog: pinging every second" "$work/onboard.log" || fail "no watchdog"
[[ -s "$work/map.smap" ]] || fail "no map saved"
[[ "$(head -1 "$work/notify.log")" == "READY=1" ]] || fail "first notification: $(head -1 "$work/notify.log")"
# STOPPING=1 once; after it only the watchdog pings that cover the drain and the map's save.
grep -q '^STOPPING=1$' "$work/notify.log" || fail "no STOPPING=1: $(tail -2 "$work/notify.log")"
after=$(sed -n '/^STOPPING=1$/,$p' "$work/notify.log" | grep -v '^$' | tail -n +2 | sort -u)
[[ -z "$after" || "$after" == "WATCHDOG=1" ]] || fail "after STOPPING=1: $after"
pings=$(grep -c '^WATCHDOG=1$' "$work/notify.log")
[[ $pings -ge 15 ]] || fail "$pings watchdog pings in a 20 s run"
echo "deb: installed files ran the simulated rig: $(grep -c . "$work/notify.log") notifications" \
  "($pings watchdog pings), map $(du -h "$work/map.smap" | cut -f1)"
