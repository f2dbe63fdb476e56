#!/usr/bin/env python3
"""Writes the committed seed inputs of the fuzz targets (test/fuzz/corpus/<target>/), small files in the layouts the
package reads, built like the unit tests' inputs (test/io, test/ros). scripts/fuzz.sh adds the repository's config
files and models at run time. Run from anywhere: python3 test/fuzz/make_seeds.py"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def out(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# ---- pointcloud2: header (see pointcloud2_fuzz.cpp) then data -------------------------------------------------------
NAMES = ["x", "y", "z", "intensity", "i", "reflectivity", "ring", "time", "t", "timestamp", "rgb"]
INT8, UINT8, INT16, UINT16, INT32, UINT32, FLOAT32, FLOAT64 = range(1, 9)
FMT = {INT8: "b", UINT8: "B", INT16: "h", UINT16: "H", INT32: "i", UINT32: "I", FLOAT32: "f", FLOAT64: "d"}


def cloud(fields, points, point_step, width=None, height=1, pad=0, big=False, flags=0b1100, scale=255.0, sec=0):
    width = len(points) // height if width is None else width
    row_step = width * point_step + pad
    e = ">" if big else "<"
    head = struct.pack("<B", len(fields))
    for name, off, dt in fields:
        head += struct.pack("<BIBB", NAMES.index(name), off, dt, 1)
    head += struct.pack("<IIIIBdII", width, height, point_step, row_step, flags | (1 if big else 0), scale, sec, 0)
    data = b""
    for r in range(height):
        row = b""
        for p in points[r * width:(r + 1) * width]:
            pt = bytearray(point_step)
            for (name, off, dt), v in zip(fields, p):
                struct.pack_into(e + FMT[dt], pt, off, v)
            row += bytes(pt)
        data += row + bytes(pad)
    return head + data


pts = [(1.0 + k, -2.0 + 0.5 * k, -1.5, 0.1 * k, k % 64, 0.001 * k) for k in range(6)]
velodyne = [("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32), ("intensity", 12, FLOAT32), ("ring", 16, UINT16),
            ("time", 18, FLOAT32)]
out("pointcloud2", "velodyne", cloud(velodyne, pts, 22))
out("pointcloud2", "velodyne_big_endian", cloud(velodyne, pts, 22, big=True))
ouster = [("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32), ("intensity", 16, FLOAT32), ("t", 20, UINT32),
          ("reflectivity", 24, UINT16), ("ring", 26, UINT8)]
out("pointcloud2", "ouster_organized",
    cloud(ouster, [(p[0], p[1], p[2], 300.0 * p[3], 1000 * k, 7, p[4]) for k, p in enumerate(pts)], 48, height=2, pad=4))
out("pointcloud2", "uint8_intensity_nan",
    cloud([("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32), ("intensity", 12, UINT8)],
          [(math.nan, 0.0, 0.0, 3)] + [(p[0], p[1], p[2], 200) for p in pts], 16))
out("pointcloud2", "float64_absolute_time",
    cloud([("x", 0, FLOAT64), ("y", 8, FLOAT64), ("z", 16, FLOAT64), ("i", 24, INT16), ("timestamp", 26, FLOAT64)],
          [(p[0], p[1], p[2], 1000, 1.7e9 + 0.001 * k) for k, p in enumerate(pts)], 34, flags=0b00100100, sec=1700000000))
out("pointcloud2", "xyz_only", cloud([("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32)], pts, 12, flags=0))
out("pointcloud2", "empty", cloud(velodyne, [], 22))

# ---- kitti_io: selector digit then the file (see kitti_io_fuzz.cpp) --------------------------------------------------
out("kitti_io", "object_labels", "0Car 0.00 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57\n"
    "\nPedestrian 0.50 1 0.1 1 2 3 4 1.7 0.6 0.8 1 1.6 12 0.3\n"
    "DontCare -1 -1 -10 356.4 195.81 374.1 216.65 -1 -1 -1 -1000 -1000 -1000 -10\n")
out("kitti_io", "object_results", "0Car -1 -1 0.1 10 20 30 40 1.5 1.6 4 1 1.7 10 0.2 0.93\n")
out("kitti_io", "tracking_labels", "10 1 Car 0 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57\n"
    "0 -1 DontCare -1 -1 -10.000000 356.400000 195.810000 374.100000 216.650000 -1000.000000 -1000.000000 "
    "-1000.000000 -10.000000 -1.000000 -1.000000 -1.000000\n"
    "3 7 Cyclist 2 1 -0.5 10 20 30 40 1.7 0.6 1.8 4 1.6 20 -0.4 0.5\n")
P = "7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 7.215377e+02 1.728540e+02 2.163791e-01 " \
    "0.000000e+00 0.000000e+00 1.000000e+00 2.745884e-03"
R = "9.999239e-01 9.837760e-03 -7.445048e-03 -9.869795e-03 9.999421e-01 -4.278459e-03 7.402527e-03 4.351614e-03 " \
    "9.999631e-01"
TR = "7.533745e-03 -9.999714e-01 -6.166020e-04 -4.069766e-03 1.480249e-02 7.280733e-04 -9.998902e-01 -7.631618e-02 " \
     "9.998621e-01 7.523790e-03 1.480755e-02 -2.717806e-01"
IMU = "9.999976e-01 7.553071e-04 -2.035826e-03 -8.086759e-01 -7.854027e-04 9.998898e-01 -1.482298e-02 3.195559e-01 " \
      "2.024406e-03 1.482454e-02 9.998881e-01 -7.997231e-01"
out("kitti_io", "calib_object", f"2P0: {P}\nP1: {P}\nP2: {P}\nP3: {P}\nR0_rect: {R}\nTr_velo_to_cam: {TR}\n"
    f"Tr_imu_to_velo: {IMU}\n")
out("kitti_io", "calib_tracking", f"2P0 {P}\nP1 {P}\nP2 {P}\nP3 {P}\nR_rect {R}\nTr_velo_cam {TR}\nTr_imu_velo {IMU}\n")
out("kitti_io", "poses", "3" + "".join(f"1 0 0 {0.1 * k} 0 1 0 0 0 0 1 {1.2 * k}\n" for k in range(4)))
oxts = "49.011212804408 8.4228850417969 112.83492279053 0.022447 1e-05 -1.2219096732051 -3.3256321640686 " \
       "1.1384311814592 3.5147680214713 0.037625160413037 -0.03878884255623 -0.29437452763793 0.037166856911681 " \
       "9.9957015129717 -0.30581030960531 -0.19635662515203 9.9942128010936 -0.017332142869546 0.024792163815438 " \
       "0.14511808479348 -0.017498934149631 0.021393359392165 0.14563031426063 0.49229361157748 0.068883960397178 " \
       "4 10 4 4 0\n"
out("kitti_io", "oxts", "4" + oxts + oxts.replace("49.011212804408", "49.011222804408"))
out("kitti_io", "per_class_csv", "5" "0,2,786.7492,180.1760,1241.0000,374.0000,12.2286,1.5206,1.6824,4.4501,2.9312,"
    "1.6089,6.4281,-1.5828,-2.0107\n4,1,10,20,30,40,0.9,1.7,0.6,0.8,1,1.6,12,0.3,0.4\n")
out("kitti_io", "velodyne", b"6" + b"".join(struct.pack("<4f", *p[:3], 0.25) for p in pts))


def det_cache(key, entries):
    b = b"RET3DDET" + struct.pack("<I", 1) + struct.pack("<Q", len(key)) + key.encode() + struct.pack("<Q", len(entries))
    for seq, frame, boxes, dim in entries:
        b += struct.pack("<Q", len(seq)) + seq.encode() + struct.pack("<iQQ", frame, len(boxes), dim)
        for (x, y, label) in boxes:
            b += struct.pack("<9d", x, y, -1.0, 4.0, 1.8, 1.5, 0.3, 1.0, 0.0) + struct.pack("<fiII", 0.9, label, 3, 120)
        b += struct.pack(f"<{len(boxes) * dim}f", *[0.5] * (len(boxes) * dim))
    return b


out("kitti_io", "detection_cache", b"7" + det_cache("fuzz", [("0000", 0, [(10.0, 1.0, 1), (20.0, -3.0, 3)], 4),
                                                            ("0001", 5, [], 0)]))

# ---- config: selector digit then YAML; scripts/fuzz.sh adds config/**.yaml --------------------------------------------
out("config", "tracker_bad_value", "1max_age: -3\n")
out("config", "detector_unknown_key", "0model:\n  geometry:\n    resolution: 0.2\n  typo: 1\n")
out("config", "intra_flow", "2{model: {radius: 4, rounds: 2}, train: {epochs: [1]}}\n")
out("config", "inter_anchor", "3model: &m {c_enc: 32}\ntrain: *m\n")

# ---- bag_check: '0' + a bag file, or '1' + bytes that drive the bag writer --------------------------------------------
try:
    import rosbag
    import rospy
    from geometry_msgs.msg import TransformStamped
    from sensor_msgs.msg import PointCloud2, PointField
    from tf2_msgs.msg import TFMessage
    import tempfile

    def pc2(stamp, n):
        m = PointCloud2()
        m.header.stamp = stamp
        m.header.frame_id = "velodyne"
        m.fields = [PointField(name, off, PointField.FLOAT32, 1) for name, off in
                    (("x", 0), ("y", 4), ("z", 8), ("intensity", 12))]
        m.height, m.width, m.point_step, m.row_step = 1, n, 16, 16 * n
        m.data = b"".join(struct.pack("<4f", 1.0 + k, 2.0, -1.0, 0.5) for k in range(n))
        return m

    def tf(stamp, parent, child, z):
        t = TransformStamped()
        t.header.stamp, t.header.frame_id, t.child_frame_id = stamp, parent, child
        t.transform.translation.z = z
        t.transform.rotation.w = 1.0
        return TFMessage([t])

    for name, compression in (("bag_plain", "none"), ("bag_bz2", "bz2"), ("bag_lz4", "lz4")):
        path = os.path.join(tempfile.mkdtemp(), "seed.bag")
        with rosbag.Bag(path, "w", compression=compression) as bag:
            t0 = rospy.Time(1000000000)
            bag.write("/tf_static", tf(t0, "base_link", "velodyne", 1.73), t0)
            for k in range(3):
                t = t0 + rospy.Duration(0.1 * k)
                bag.write("/tf", tf(t, "odom", "base_link", 0.0), t)
                bag.write("/points", pc2(t, 4), t)
        with open(path, "rb") as f:
            out("bag_check", name, b"0" + f.read())
        os.remove(path)
        os.rmdir(os.path.dirname(path))
except ImportError as e:
    print("no python3-rosbag: bag seeds not written (%s)" % e)
out("bag_check", "writer_random", bytes([ord("1")]) + bytes((k * 37 + 11) % 256 for k in range(512)))

# ---- model_file: scripts/fuzz.sh adds models/**.pt; two small refusals here -------------------------------------------
out("model_file", "detector_truncated", b"0RET3DMDL" + struct.pack("<IQ", 1, 40) + b"format_version: 1\n")
out("model_file", "detector_version2", b"0RET3DMDL" + struct.pack("<IQ", 2, 0) + struct.pack("<QQ", 0, 0))
