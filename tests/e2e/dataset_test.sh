#!/usr/bin/env bash
# semap-dataset on real recordings (../shared/data/real): Redwood's five frames labelled by the
# shipped network and by label images semap-segment made beforehand, a TUM folder made of the
# one TUM pair, the same TUM folder with a pose line that does not parse and a depth image that
# is not 16-bit (named, counted, exit 2), and a KITTI odometry sequence made of the real scan:
# whole, labelled through an image, and next to a truncated scan.
#   dataset_test.sh SEMAP_DATASET SEMAP_SEGMENT MODEL_CARD REAL_DATA_DIR
set -euo pipefail
tool="$1" segment="$2" card="$3" real="$4"
for d in redwood tum_pair kitti_odometry_00; do
  if [[ ! -d "$real/$d" ]]; then
    echo "SKIP: $real/$d is absent (see ../shared/data/real/README.md)"
    exit 0
  fi
done
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

# The same frames from label images made beforehand: the map the network's labels give.
"$segment" --card "$card" --out "$work/labels" "$real"/redwood/color/*.jpg >"$work/segment.log"
"$tool" redwood "$real/redwood" --labels "$work/labels" --num-classes 8 --out "$work/redwood-labels" \
  >"$work/redwood-labels.log"
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/redwood-labels/summary.json")
[[ "$mapped" == 5 ]] || { echo "FAIL: redwood --labels: $mapped of 5 frames mapped"; exit 1; }
from_labels=$(field "$work/redwood-labels/summary.json" occupied_cells)
# Label images hold hard labels, the network soft ones: the same cells within a few per cent.
((from_labels * 100 > cells * 90 && from_labels * 100 < cells * 110)) ||
  { echo "FAIL: redwood --labels: $from_labels occupied cells, $cells from the network"; exit 1; }
echo "redwood --labels: 5 frames mapped, $from_labels occupied cells"

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
# KITTI odometry: sequence 00's first scan and poses, calib.txt with sequence 00's Tr.
seq="$work/kitti/sequences/00"
mkdir -p "$seq/velodyne" "$work/kitti/poses"
cp "$real/kitti_odometry_00/sequences/00/velodyne/000000.bin" "$seq/velodyne/"
head -2 "$real/kitti_odometry_00/sequences/00/times.txt" >"$seq/times.txt"
head -2 "$real/kitti_odometry_00/poses/00.txt" >"$work/kitti/poses/00.txt"
cat >"$seq/calib.txt" <<'CALIB'
P0: 718.856 0 607.1928 0 0 718.856 185.2157 0 0 0 1 0
P2: 718.856 0 607.1928 45.38225 0 718.856 185.2157 -0.1130887 0 0 1 0.003779761
Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 -7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01
CALIB
"$tool" kitti-odometry "$seq" --no-labels --out "$work/kitti-whole" >"$work/kitti-whole.log"
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/kitti-whole/summary.json")
[[ "$mapped" == 1 ]] || { echo "FAIL: kitti-odometry: $mapped of 1 scans mapped"; exit 1; }
whole=$(field "$work/kitti-whole/summary.json" occupied_cells)
((whole > 100000)) || { echo "FAIL: kitti-odometry: $whole occupied cells"; exit 1; }
echo "kitti-odometry whole scan: $whole occupied cells"

# Labelled through an image_2 frame (a real street-less image: only the projection is tested):
# only the points the camera sees reach the map.
mkdir -p "$seq/image_2"
cp "$real/tum_pair/TUM_color.png" "$seq/image_2/000000.png"
"$tool" kitti-odometry "$seq" --segmenter "$card" --out "$work/kitti-seen" >"$work/kitti-seen.log"
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/kitti-seen/summary.json")
[[ "$mapped" == 1 ]] || { echo "FAIL: kitti-odometry --segmenter: $mapped scans mapped"; exit 1; }
seen=$(field "$work/kitti-seen/summary.json" occupied_cells)
((seen > 100 && seen * 4 < whole)) ||
  { echo "FAIL: kitti-odometry --segmenter: $seen occupied cells of $whole"; exit 1; }
echo "kitti-odometry through image_2: $seen occupied cells"

# A truncated scan (not a multiple of 16 bytes) is named and skipped; exit 2.
rm -r "$seq/image_2"
head -c 1000 "$seq/velodyne/000000.bin" >"$seq/velodyne/000001.bin"
status=0
"$tool" kitti-odometry "$seq" --no-labels --out "$work/kitti-bad" >"$work/kitti-bad.log" 2>&1 ||
  status=$?
[[ $status == 2 ]] || { echo "FAIL: kitti-odometry with a bad scan exited $status, not 2"; exit 1; }
grep -q 'velodyne/000001.bin' "$work/kitti-bad/summary.json" ||
  { echo "FAIL: the truncated scan is not named"; cat "$work/kitti-bad/summary.json"; exit 1; }
mapped=$(sed -n 's/.*"mapped": \([0-9]*\).*/\1/p' "$work/kitti-bad/summary.json")
[[ "$mapped" == 1 ]] || { echo "FAIL: kitti-odometry with a bad scan: $mapped mapped, not 1"; exit 1; }
echo "kitti-odometry with a truncated scan: exit 2, named, the good scan mapped"
echo PASS
