#!/usr/bin/env bash
# The disk fills while semap-onboard checkpoints its map (docs/reliability.md). The simulated
# robot checkpoints every second while a planner-side listener follows its health over DDS:
#
#   ulimit  the process runs under a 4 MiB file-size limit (ulimit -f; semap-onboard ignores
#           SIGXFSZ, so writes fail with EFBIG) and records its sensor streams and outputs
#           (--record rec.mcap): the recording reaches the limit in a few seconds, the checkpoint
#           log a few seconds into mapping, and the map saved at SIGTERM does not fit either. The
#           recording must replay up to its last whole chunk, with no torn chunk at its end.
#   tmpfs   (root, mount permitted; else skipped with exit 77) the map lives on a 64 MiB tmpfs
#           that a filler file leaves 3 MiB of: checkpoints fail with ENOSPC; then the filler
#           is deleted, writing must resume and the map saved at SIGTERM fits.
#
# Both: the process lives on until SIGTERM and exits with the status of its design (3: the map
# could not be saved; 0: it was); the log names the file and the errno text once (no flood);
# the health report carries the failures while the estimation, mapping and DDS stages keep
# their rates; the summary counts them; the checkpoint log has no torn record and resumes
# (semap-onboard --resume) with its last checkpoint's scans.
set -euo pipefail
onboard="$1" listener="$2" config="$3" xml="$4" mode="$5"
export CYCLONEDDS_URI="file://$xml"
domain=$(((RANDOM % 200) + 20))
ns="full$$"
work=$(mktemp -d)
disk="$work/disk"
mkdir -p "$disk"
cleanup() {
  kill -9 ${pids:-} 2>/dev/null || true
  if [[ $mode == tmpfs ]]; then umount "$disk" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "e2e disk full ($mode): $*"
  exit 1
}
say() { echo "e2e disk full ($mode): $*"; }

if [[ $mode == tmpfs ]]; then
  if [[ $(id -u) -ne 0 ]] || ! mount -t tmpfs -o size=64m semap-e2e "$disk" 2>/dev/null; then
    say "skipped: mounting a tmpfs needs root and mount permission"
    exit 77
  fi
  # 3 MiB left for the map: its checkpoint log fills them a few seconds into mapping.
  fallocate -l 61M "$disk/filler" 2>/dev/null || head -c $((61 * 1024 * 1024)) /dev/zero >"$disk/filler"
  errno_text="No space left on device"
else
  errno_text="File too large"
fi

sed -e "s#save_path: .*#save_path: $disk/map.smap\n  checkpoint_s: 1#" \
  -e "s#^dds:#dds:\n  namespace: $ns#" "$config" >"$work/sim.yaml"
grep -q "checkpoint_s: 1" "$work/sim.yaml" && grep -q "namespace: $ns" "$work/sim.yaml" ||
  fail "could not write the run's config"

"$listener" --domain "$domain" --ns "$ns" --seconds 150 --classes 8 --health \
  >"$work/listener.log" 2>&1 &
listener_pid=$!
if [[ $mode == tmpfs ]]; then
  "$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" >"$work/run.log" 2>&1 &
else
  (
    ulimit -f 4096 # KiB: 4 MiB per file
    exec "$onboard" --config "$work/sim.yaml" --duration 120 --domain "$domain" \
      --record "$disk/rec.mcap"
  ) >"$work/run.log" 2>&1 &
fi
pid=$!
pids="$pid $listener_pid"

# wait_for PATTERN SECONDS: until the robot's log has the line, while the robot runs.
wait_for() {
  for _ in $(seq 1 "$2"); do
    grep -q "$1" "$work/run.log" && return 0
    kill -0 "$pid" 2>/dev/null || {
      cat "$work/run.log"
      fail "semap-onboard ended while waiting for '$1'"
    }
    sleep 1
  done
  cat "$work/run.log"
  fail "no '$1' after $2 s"
}
# Mapping starts once the heading is known (about 15 s on this machine).
wait_for "map checkpoint: $disk/map.smap.log: write: $errno_text" 100
say "first failure: $(grep -m1 "map checkpoint: .*$errno_text" "$work/run.log")"
# Failing checkpoints while the robot drives on: long enough for several health reports.
sleep 8
if [[ $mode == tmpfs ]]; then
  rm "$disk/filler" # room again
  wait_for "map checkpoint: writing again after [0-9]* failures" 20
  sleep 4
fi
kill -TERM "$pid"
status=0
wait "$pid" || status=$?
sleep 2 # the listener takes the last health report
kill -TERM "$listener_pid" 2>/dev/null || true
wait "$listener_pid" || true
sed -n '/summary/,$p' "$work/run.log"

# Alive to the end, and the exit status says whether the map was saved.
grep -q "terminate called\|Aborted" "$work/run.log" && fail "a writer's exception reached terminate"
if [[ $mode == tmpfs ]]; then
  [[ $status -eq 0 ]] || fail "exit status $status; the map should have been saved (0)"
  grep -q "map saved to $disk/map.smap" "$work/run.log" || fail "no map saved once there was room"
else
  [[ $status -eq 3 ]] || fail "exit status $status; a map not saved is exit 3"
  grep -q "map save failed  : $disk/map.smap: .*$errno_text" "$work/run.log" ||
    fail "the summary does not name the map that was not saved"
  grep -q "map not saved: $disk/map.smap: .*$errno_text; $disk/map.smap.log keeps" \
    "$work/run.log" || fail "the log does not name the map that was not saved"
  [[ ! -e "$disk/map.smap" ]] || fail "a map file appeared although its save failed"
fi

# Logged once as an error naming the file and errno text, then at most every 30 s.
errors=$(grep -c "\[mapping\] \[error\] map checkpoint" "$work/run.log" || true)
[[ $errors -ge 1 && $errors -le 4 ]] || fail "$errors checkpoint error lines: not rate-limited"

# The summary counts the failures and says where the log stands.
failures=$(grep -o "map checkpoint   : .*, \([0-9]*\) write failures" "$work/run.log" |
  grep -o "[0-9]* write failures" | grep -o "[0-9]*") || fail "no checkpoint summary line"
[[ $failures -ge 3 ]] || fail "only $failures write failures counted"
grep -q "checkpoint fails : .* the log holds the map of scan [0-9]*; last error: .*$errno_text" \
  "$work/run.log" || fail "no checkpoint failure summary line"
committed=$(grep -o "the log holds the map of scan [0-9]*" "$work/run.log" | grep -o "[0-9]*$")
scans=$(grep -o "^mapping          : [0-9]* scans" "$work/run.log" | grep -o "[0-9]* scans" |
  grep -o "[0-9]*")

# Health over DDS: the failures while estimation, mapping and the map publisher kept going.
failing_reports=$(grep "writer map_checkpoint [^|]* failing 1 error '[^']*$errno_text'" \
  "$work/listener.log" || true)
[[ -n $failing_reports ]] || {
  tail -5 "$work/listener.log"
  fail "no health report with the checkpoint failing"
}
busy=$(echo "$failing_reports" | awk '{
  for (i = 1; i < NF; ++i) if ($i == "stage") rate[$(i + 1)] = $(i + 3)
  if (rate["estimation"] > 100 && rate["mapping"] > 0 && rate["dds_map"] > 0) ++n
} END { print n + 0 }')
[[ $busy -ge 2 ]] || fail "only $busy failing health reports with the stages running"
say "$failures write failures, $(echo "$failing_reports" | wc -l) health reports failing" \
  "($busy with estimation, mapping and dds_map running); $scans scans mapped"

if [[ $mode == tmpfs ]]; then
  grep -q "checkpoint fails : .* writing again at exit" "$work/run.log" ||
    fail "the summary does not say writing resumed"
  grep -q "writer map_checkpoint [^|]* failing 0 " <(grep -A1000 "failing 1" "$work/listener.log") ||
    fail "no health report after the recovery"
  [[ $committed -eq $scans ]] || fail "the log holds scan $committed of $scans after recovery"
else
  [[ $scans -gt $((committed + 10)) ]] || fail "mapping stopped with the checkpoint ($scans scans)"
  size=$(stat -c %s "$disk/map.smap.log")
  [[ $size -le $((4096 * 1024)) ]] || fail "the log is past the limit ($size bytes)"
  # The recorder: counted, named, in health; its files whole and replayable to their end.
  grep -Eq "recording        : $disk/rec.mcap: .* [1-9][0-9]* write failures \((still failing at exit|writing again); last error: $disk/rec.mcap: write: $errno_text\)" \
    "$work/run.log" || fail "the recording's failures are not in the summary"
  grep -q "\[recorder\] \[error\] recording: $disk/rec.mcap: write: $errno_text" \
    "$work/run.log" || fail "the recording's failure is not logged"
  recorder_errors=$(grep -c "\[recorder\] \[error\]" "$work/run.log" || true)
  [[ $recorder_errors -le 5 ]] || fail "$recorder_errors recorder error lines: not rate-limited"
  grep -q "writer recorder [^|]* failing 1 error '[^']*$errno_text'" "$work/listener.log" ||
    fail "no health report with the recorder failing"
  "$onboard" --replay "$disk/rec.mcap" --pace fast --save "$work/replay.smap" --domain "$domain" \
    >"$work/replay.log" 2>&1 || true
  grep -q "^replay           : [1-9][0-9]* CAN frames" "$work/replay.log" || {
    cat "$work/replay.log"
    fail "the recording does not replay"
  }
  # Either its end fitted under the limit at exit (a complete file: the chunks that did not
  # fit are lost, the others are whole), or it reads to its last whole chunk, which is where the
  # file ends (a failed chunk was cut off again, nothing torn).
  size=$(stat -c %s "$disk/rec.mcap")
  ! grep -q "^replay           : .*damaged" "$work/replay.log" ||
    grep -q "^replay           : .*damaged: $disk/rec.mcap: truncated at byte $size:" \
      "$work/replay.log" || {
    grep "^replay  " "$work/replay.log"
    fail "the recording does not end after its last whole chunk ($size bytes)"
  }
  say "recording: $(grep -o "[0-9]* write failures ([a-z ]*" "$work/run.log"), replayed:" \
    "$(grep "^replay  " "$work/replay.log")"
fi

# The checkpoint log: no torn record, and --resume loads its last checkpoint.
"$onboard" --config "$work/sim.yaml" --duration 3 --domain "$domain" --resume \
  >"$work/resume.log" 2>&1 || true
grep -q "map checkpoint: .*record at byte" "$work/resume.log" && {
  cat "$work/resume.log"
  fail "the log had a torn or damaged record"
}
resumed=$(grep -o "map resumed from $disk/map.smap.log: [0-9]* blocks of [0-9]* scans" \
  "$work/resume.log") || {
  cat "$work/resume.log"
  fail "the checkpoint log did not resume"
}
blocks=$(echo "$resumed" | sed 's/.*: \([0-9]*\) blocks of \([0-9]*\) scans/\1/')
resumed_scans=$(echo "$resumed" | sed 's/.*: \([0-9]*\) blocks of \([0-9]*\) scans/\2/')
[[ $resumed_scans -eq $committed && $blocks -gt 100 ]] ||
  fail "resumed $blocks blocks of $resumed_scans scans; the log's last checkpoint is scan $committed"
say "passed: exit $status, resumed $blocks blocks of $resumed_scans scans"
