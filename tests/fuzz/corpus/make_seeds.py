#!/usr/bin/env python3
"""Writes the seed corpora of frame_convert_fuzz, map_cloud_fuzz, dds_from_msg_fuzz and
kitti_readers_fuzz (valid inputs in each target's input layout). Usage: make_seeds.py JPEG,
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
