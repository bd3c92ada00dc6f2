# Sourced by the onboard e2e tests. check_stage_counts LOG: reads semap-onboard's exit summary
# and checks that stopping drained every ring through its stage: each colour frame taken became
# a cloud or is counted with its reason, and each cloud is in the map or counted as dropped by
# the cloud ring (which drops the oldest rather than stall perception). Leaves frames, posed,
# skipped, unpaired, bad, unposed, uncertain, scans and cloud_drops set; uses the caller's num
# and fail.
check_stage_counts() {
  local log="$1" perception figure
  perception=$(grep '^perception *: ' "$log" || true)
  read -r frames posed skipped unpaired bad unposed uncertain < <(sed -n 's/^perception *: \([0-9]*\) frames, \([0-9]*\) clouds mapped ([0-9]* points), \([0-9]*\) passed over, \([0-9]*\) unpaired, \([0-9]*\) bad, \([0-9]*\) without a pose, \([0-9]*\) posed too uncertainly.*/\1 \2 \3 \4 \5 \6 \7/p' <<<"$perception")
  scans=$(sed -n 's/^mapping *: \([0-9]*\) scans.*/\1/p' "$log")
  cloud_drops=$(sed -n 's/^ring drops *: .*, clouds \([0-9]*\)$/\1/p' "$log")
  for figure in frames posed skipped unpaired bad unposed uncertain scans cloud_drops; do
    num "$figure" "${!figure:-}"
  done
  [[ $((posed + skipped + unpaired + bad + unposed + uncertain)) -eq "$frames" ]] ||
    fail "perception: $frames frames but $posed clouds + $skipped + $unpaired + $bad + $unposed + $uncertain lost"
  [[ $((scans + cloud_drops)) -eq "$posed" ]] ||
    fail "perception made $posed clouds; mapped $scans, the ring dropped $cloud_drops"
}
