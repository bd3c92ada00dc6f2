#!/usr/bin/env bash
# semap-onboard on the simulated rig with a model card that does not exist: perception is
# disabled with an error naming the card, while the robot keeps estimating and publishing its
# pose; at exit it reports failure (no map), never a crash.
set -euo pipefail
onboard="$1" config="$2" xml="$3"
export CYCLONEDDS_URI="file://$xml"
domain=$(( (RANDOM % 200) + 20 ))
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e 's|^  model_card: .*|  model_card: '"$work"'/missing-card.yaml|' \
    -e 's|^  save_path: .*|  save_path: '"$work"'/map.smap|' "$config" >"$work/robot.yaml"
grep -q "missing-card.yaml" "$work/robot.yaml" || { echo "config edit failed"; exit 1; }
status=0
"$onboard" --config "$work/robot.yaml" --duration 8 --domain "$domain" >"$work/onboard.log" 2>&1 ||
  status=$?
sed -n '/summary/,$p' "$work/onboard.log"
[[ "$status" -eq 1 ]] || { echo "exit status $status, expected 1"; cat "$work/onboard.log"; exit 1; }
grep -q "perception disabled.*missing-card.yaml" "$work/onboard.log" || {
  echo "no error naming the card"; cat "$work/onboard.log"; exit 1; }
grep -q "gated out), initialised=yes" "$work/onboard.log" || { echo "not initialised"; exit 1; }
odometry=$(sed -n 's/^dds *: \([0-9]*\) odometry samples.*/\1/p' "$work/onboard.log")
[[ -n "$odometry" && "$odometry" -gt 100 ]] || { echo "odometry '$odometry'"; exit 1; }
echo "no-perception: exit 1 as expected, $odometry odometry samples"
