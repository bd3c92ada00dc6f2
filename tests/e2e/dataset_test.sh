#!/usr/bin/env bash
# semap-dataset on real recordings (../shared/data/real): Redwood's five frames labelled by the
# shipped network, a TUM folder made of the one TUM pair, and the same TUM folder with a pose
# line that does not parse and a depth image that is not 16-bit: named, counted, exit 2.
#   dataset_test.sh SEMAP_DATASET MODEL_CARD REAL_DATA_DIR
set -euo pipefail
tool="$1" card="$2" real="$3"
if [[ ! -d "$real/redwood" || ! -d "$real/tum_pair" ]]; then
  echo "SKIP: $real/redwood or $real/tum_pair is absent (see ../shared/data/real/README.md)"
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
field() { sed -n "s/.*\"$2\": \([0-9.]*\).*/\1/p" "$1" | head -1; }

"$tool" redwood "$real/redwood" --segmenter "$card" --out "$work/redwood" >"$work/redwood.log"
for f in map.smap map.ply top.png summary.json; do
  [[ -s "$work/redwood/$f" ]] || { echo "FAIL: redwood: no $f"; exit 1; }
done
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/redwood/summary.json")
[[ "$mapped" == 5 ]] || { echo "FAIL: redwood: $mapped of 5 frames mapped"; exit 1; }
cells=$(field "$work/redwood/summary.json" occupied_cells)
((cells > 1000)) || { echo "FAIL: redwood: $cells occupied cells"; exit 1; }
echo "redwood: 5 frames mapped, $cells occupied cells"

# A TUM folder: the pair as frames at t = 1.0 and 1.1, ground truth around them.
tum="$work/tum"
mkdir -p "$tum/rgb" "$tum/depth"
cp "$real/tum_pair/TUM_color.png" "$tum/rgb/1.000000.png"
cp "$real/tum_pair/TUM_color.png" "$tum/rgb/1.100000.png"
cp "$real/tum_pair/TUM_depth.png" "$tum/depth/1.000000.png"
cp "$real/tum_pair/TUM_depth.png" "$tum/depth/1.100000.png"
printf '# colour\n1.000000 rgb/1.000000.png\n1.100000 rgb/1.100000.png\n' >"$tum/rgb.txt"
printf '# depth\n1.000000 depth/1.000000.png\n1.100000 depth/1.100000.png\n' >"$tum/depth.txt"
printf '# ground truth\n0.95 0 0 0 0 0 0 1\n1.02 0.01 0 0 0 0 0 1\n1.09 0.02 0 0 0 0 0 1\n1.16 0.03 0 0 0 0 0 1\n' \
  >"$tum/groundtruth.txt"
"$tool" tum "$tum" --no-labels --intrinsics 525,525,319.5,239.5 --out "$work/tum-out" \
  >"$work/tum.log"
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/tum-out/summary.json")
[[ "$mapped" == 2 ]] || { echo "FAIL: tum: $mapped of 2 frames mapped"; exit 1; }
echo "tum: 2 frames mapped at depth / 5000"

# Bad input: a ground-truth line that does not parse, an 8-bit depth image.
printf 'not a pose line\n' >>"$tum/groundtruth.txt"
cp "$real/tum_pair/TUM_color.png" "$tum/depth/1.100000.png"  # 8-bit, three channels
status=0
"$tool" tum "$tum" --no-labels --intrinsics 525,525,319.5,239.5 --out "$work/tum-bad" \
  >"$work/tum-bad.log" 2>&1 || status=$?
[[ $status == 2 ]] || { echo "FAIL: tum with bad input exited $status, not 2"; exit 1; }
grep -q 'groundtruth.txt:6' "$work/tum-bad/summary.json" ||
  { echo "FAIL: the bad pose line is not named"; cat "$work/tum-bad/summary.json"; exit 1; }
grep -q 'depth/1.100000.png' "$work/tum-bad/summary.json" ||
  { echo "FAIL: the 8-bit depth image is not named"; cat "$work/tum-bad/summary.json"; exit 1; }
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/tum-bad/summary.json")
[[ "$mapped" == 1 ]] || { echo "FAIL: tum with bad input: $mapped frames mapped, not 1"; exit 1; }
echo "tum with bad input: exit 2, both problems named, the good frame mapped"
echo PASS
