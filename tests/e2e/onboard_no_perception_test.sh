#!/usr/bin/env bash
# semap-onboard on the simulated rig whose segmentation network does not load (a model card
# naming a damaged .onnx): perception is disabled with an error naming the model, while the
# robot keeps estimating and publishing its pose; at exit it reports failure (no map), never a
# crash. A card that does not exist is a configuration error instead: start-up stops with exit
# status 2 naming the config file, line and key.
set -euo pipefail
onboard="$1" config="$2" xml="$3"
export CYCLONEDDS_URI="file://$xml"
domain=$(( (RANDOM % 200) + 20 ))
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

sed -e 's|^  model_card: .*|  model_card: '"$work"'/missing-card.yaml|' "$config" >"$work/typo.yaml"
status=0
"$onboard" --config "$work/typo.yaml" --duration 8 >"$work/typo.log" 2>&1 || status=$?
line=$(grep -n "^  model_card:" "$work/typo.yaml" | cut -d: -f1)
[[ "$status" -eq 2 ]] || { echo "missing card: exit status $status, expected 2"; cat "$work/typo.log"; exit 1; }
grep -q "$work/typo.yaml:$line: key 'segmenter.model_card': .*missing-card.yaml" "$work/typo.log" || {
  echo "missing card: no error naming the file, line $line and key"; cat "$work/typo.log"; exit 1; }

cp models/semap-seg.yaml "$work/card.yaml"
head -c 4096 /dev/urandom >"$work/semap-seg.onnx"
sed -e 's|^  model_card: .*|  model_card: '"$work"'/card.yaml|' \
    -e 's|^  save_path: .*|  save_path: '"$work"'/map.smap|' "$config" >"$work/robot.yaml"
grep -q "$work/card.yaml" "$work/robot.yaml" || { echo "config edit failed"; exit 1; }
status=0
"$onboard" --config "$work/robot.yaml" --duration 8 --domain "$domain" >"$work/onboard.log" 2>&1 ||
  status=$?
sed -n '/summary/,$p' "$work/onboard.log"
[[ "$status" -eq 1 ]] || { echo "exit status $status, expected 1"; cat "$work/onboard.log"; exit 1; }
grep -q "perception disabled.*semap-seg.onnx" "$work/onboard.log" || {
  echo "no error naming the model"; cat "$work/onboard.log"; exit 1; }
grep -q "gated out), initialised=yes" "$work/onboard.log" || { echo "not initialised"; exit 1; }
odometry=$(sed -n 's/^dds *: \([0-9]*\) odometry samples.*/\1/p' "$work/onboard.log")
[[ -n "$odometry" && "$odometry" -gt 100 ]] || { echo "odometry '$odometry'"; exit 1; }
echo "no-perception: a missing card stops start-up (exit 2, $(basename "$work/typo.yaml"):$line named);" \
  "a damaged network: exit 1 as expected, $odometry odometry samples"
