#!/usr/bin/env python3
"""Writes the seed corpora of frame_convert_fuzz, map_cloud_fuzz, dds_from_msg_fuzz,
kitti_readers_fuzz and the dataset parsers' tum_files_fuzz, redwood_files_fuzz and
kitti_odometry_files_fuzz (valid inputs in each target's input layout). Usage: make_seeds.py JPEG,
where JPEG is a small baseline JPEG of 16 x 8 pixels (e.g. written with tjCompress2)."""
import os
import struct
import sys

here = os.path.dirname(os.path.abspath(__file__))


def write(target, name, data):
    os.makedirs(os.path.join(here, target), exist_ok=True)
    with open(os.path.join(here, target, name), "wb") as f:
        f.write(data)


def frame(fmt, w, h, stride, data):
    return struct.pack("<BIII", fmt, w, h, stride) + bytes(data)


# frame_convert_fuzz: format 0 YUYV, 1 MJPEG, 2 GREY, 3 Z16, 4 BGR24.
write("frame_convert_fuzz", "yuyv_4x2", frame(0, 4, 2, 8, [180, 128] * 8))
write("frame_convert_fuzz", "yuyv_padded", frame(0, 2, 2, 6, [90, 60, 200, 30, 0, 0] * 2))
write("frame_convert_fuzz", "grey_3x2_stride5", frame(2, 3, 2, 5, range(10)))
write("frame_convert_fuzz", "z16_2x2", frame(3, 2, 2, 4, [0xD2, 0x04] * 4))
write("frame_convert_fuzz", "bgr_2x2", frame(4, 2, 2, 6, range(12)))
with open(sys.argv[1], "rb") as f:
    write("frame_convert_fuzz", "mjpeg_16x8", frame(1, 16, 8, 0, f.read()))

# map_cloud_fuzz: the layout MapCloud writes (x y z rgb variance float32, class uint16).
FIELDS = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("rgb", 12, 7), ("variance", 16, 7),
          ("class", 20, 4)]


def cloud(points, width=None, height=1):
    out = bytes([len(FIELDS)])
    for name, _, _ in FIELDS:
        out += bytes([len(name)]) + name.encode()
    for _, offset, datatype in FIELDS:
        out += struct.pack("<IBI", offset, datatype, 1)
    out += struct.pack("<IIIB", height, len(points) if width is None else width, 24, 0)
    for x, y, z, rgb, var, cls in points:
        out += struct.pack("<fffIfH", x, y, z, rgb, var, cls) + b"\0\0"
    return out


write("map_cloud_fuzz", "empty", cloud([]))
write("map_cloud_fuzz", "three_points",
      cloud([(0.05, 0.15, 0.25, 0xFF0000, 0.01, 1), (1.0, -2.0, 0.5, 0x00FF00, 0.2, 7),
             (3.5, 3.5, 0.0, 0x808080, 0.0, 0xFFFF)]))
write("map_cloud_fuzz", "two_rows", cloud([(1, 2, 3, 0, 0.1, 2)] * 4, width=2, height=2))


# dds_from_msg_fuzz: selector 0 MapInfo, 1 Health, 2 Odometry.
def string(s):
    return bytes([len(s)]) + s.encode()


info = bytes([0]) + struct.pack("<iIfHH", 1700000000, 5, 0.2, 8, 3)
info += bytes([3]) + string("free") + string("road") + string("car")
info += bytes([3]) + struct.pack("<III", 0, 0x808080, 0xFF0000)
info += struct.pack("<6d", -10, -10, -2, 10, 10, 3) + struct.pack("<IQ", 42, 7)
write("dds_from_msg_fuzz", "map_info", info)
write("dds_from_msg_fuzz", "map_info_no_names",
      bytes([0]) + struct.pack("<iIfHH", 3, 0, 0.1, 16, 20) + bytes([0, 0]) +
      struct.pack("<6dIQ", 0, 0, 0, 0, 0, 0, 0, 0))
health = bytes([1]) + struct.pack("<iI", 12, 500) + bytes([2, 2, 1])
health += string("estimation") + string("can_imu")
health += bytes([0]) + struct.pack("<fIQff", 200.0, 3, 1, 0.4, 1.2)
health += bytes([1]) + struct.pack("<fIQff", 30.0, 0, 0, 8.0, 20.0)
health += bytes([1]) + struct.pack("<7Q", 1000, 2, 0, 1, 0, 0, 0)
write("dds_from_msg_fuzz", "health", health)
odom = bytes([2]) + struct.pack("<iI", 100, 250000000)
odom += struct.pack("<3d", 1.5, -2.0, 0.3) + struct.pack("<4d", 0, 0, 0.38268343, 0.92387953)
odom += struct.pack("<36d", *[0.01 if i % 7 == 0 else 0.0 for i in range(36)])
odom += struct.pack("<6d", 1.0, 0, 0, 0, 0, 0.1)
odom += struct.pack("<36d", *[0.02 if i % 7 == 0 else 0.0 for i in range(36)])
write("dds_from_msg_fuzz", "odometry", odom)

# kitti_readers_fuzz: kind 0 .bin, 1 .label, 2 poses.txt, 3 calib.txt.
write("kitti_readers_fuzz", "scan.bin",
      bytes([0]) + struct.pack("<8f", 1, 2, 3, 0.5, -4, 0, 1, 0.1))
write("kitti_readers_fuzz", "labels.label",
      bytes([1]) + struct.pack("<3I", 40, 10 | (7 << 16), 252))
write("kitti_readers_fuzz", "poses.txt", bytes([2]) + b"1 0 0 0 0 1 0 0 0 0 1 0\n"
      b"1.000000e+00 0 0 0.5 0 1 0 0 0 0 1 1.25\n\n")
write("kitti_readers_fuzz", "calib.txt", bytes([3]) +
      b"P0: 7.07e+02 0 6.0e+02 0 0 7.07e+02 1.8e+02 0 0 0 1 0\n"
      b"Tr: 4.27e-04 -9.99e-01 -8.08e-03 -1.19e-02 -7.21e-03 8.08e-03 -9.99e-01 -5.40e-02 "
      b"9.99e-01 4.85e-04 -7.20e-03 -2.92e-01\n")

# Dataset text parsers (tests/fuzz/perception): a first byte picks the file.
# tum_files_fuzz: kind 0 rgb.txt / depth.txt, 1 groundtruth.txt, 2 two lists split at NUL.
rgb = (b"# color images\n# timestamp filename\n1305031102.175304 rgb/1305031102.175304.png\n"
       b"1305031102.211214 rgb/1305031102.211214.png\n1305031102.243211 rgb/1305031102.243211.png\n")
depth = (b"# depth maps\n1305031102.160407 depth/1305031102.160407.png\n"
         b"1305031102.226738 depth/1305031102.226738.png\n1305031102.262886 depth/1305031102.262886.png\n")
write("tum_files_fuzz", "rgb.txt", bytes([0]) + rgb)
write("tum_files_fuzz", "groundtruth.txt", bytes([1]) +
      b"# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
      b"1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
      b"1305031098.6758 1.3543 0.6306 1.6360 0.6129 0.5966 -0.3316 -0.3980\n"
      b"1305031098.6858 1.3524 0.6319 1.6340 0.6123 0.5961 -0.3333 -0.3982\n")
write("tum_files_fuzz", "associate", bytes([2]) + rgb + b"\0" + depth)
write("tum_files_fuzz", "bad_lines", bytes([0]) + b"1.0x rgb/a.png\n1.0 a b\n\n,1.5,rgb/c.png\n")

# redwood_files_fuzz: kind 0 .log trajectory, 1 rgbd.match.
write("redwood_files_fuzz", "odometry.log", bytes([0]) +
      b"0\t0\t1\n   1    0    0    2\n   0    1    0    2\n   0    0    1 -0.3\n   0    0    0    1\n"
      b"1\t1\t2\n    0.999988 3.08668e-005    0.0049181      1.99962\n"
      b"-8.84184e-005     0.999932    0.0117022      1.97704\n"
      b"  -0.0049174   -0.0117024     0.999919    -0.300486\n"
      b"           0            0            0            1\n")
write("redwood_files_fuzz", "truncated.log", bytes([0]) +
      b"0 0 1\n1 0 0 0\n0 1 0 0\n1 1 2\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n7 7\n")
write("redwood_files_fuzz", "rgbd.match", bytes([1]) +
      b"depth/00000.png color/00000.jpg\ndepth/00001.png color/00001.jpg\n")

# kitti_odometry_files_fuzz: kind 0 poses, 1 times.txt, 2 calib.txt, 3 velodyne .bin.
write("kitti_odometry_files_fuzz", "poses.txt", bytes([0]) +
      b"1.000000e+00 9.043680e-12 2.326809e-11 5.551115e-17 9.043683e-12 1.000000e+00 "
      b"2.392370e-10 3.330669e-16 2.326810e-11 2.392370e-10 9.999999e-01 -4.440892e-16\n"
      b"9.999978e-01 5.272628e-04 -2.066935e-03 -4.690294e-02 -5.296506e-04 9.999992e-01 "
      b"-1.154865e-03 -2.839928e-02 2.066324e-03 1.155958e-03 9.999971e-01 8.586941e-01\n")
write("kitti_odometry_files_fuzz", "times.txt", bytes([1]) +
      b"0.000000e+00\n1.037359e-01\n2.073381e-01\n")
write("kitti_odometry_files_fuzz", "calib_odometry.txt", bytes([2]) +
      b"P0: 718.856 0 607.1928 0 0 718.856 185.2157 0 0 0 1 0\n"
      b"P2: 718.856 0 607.1928 45.38225 0 718.856 185.2157 -0.1130887 0 0 1 0.003779761\n"
      b"Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
      b"-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
      b"9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01\n")
write("kitti_odometry_files_fuzz", "calib_object.txt", bytes([2]) +
      b"P2: 700 0 600 45 0 700 180 0 0 0 1 0\nR0_rect: 1 0 0 0 0.99995 -0.01 0 0.01 0.99995\n"
      b"Tr_velo_to_cam: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 -0.3\n")
write("kitti_odometry_files_fuzz", "scan.bin",
      bytes([3]) + struct.pack("<8f", 1, 2, 3, 0.5, -4, 0, 1, 0.1))
