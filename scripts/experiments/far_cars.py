#!/usr/bin/python3
"""How many returns the simulated cars have at each range, and which of them a prediction finds (can any
detector reach Car MOTA 75 over the labels' 80 m?). For every car label of a KITTI tracking folder: its range, the
LiDAR returns inside its box (grown by 0.1 m) in the sensor frame, and whether a predicted car of the same frame lies
within 2 m of its centre (each prediction folder given). Prints recall per range band and per return count.
  scripts/experiments/far_cars.py GT_ROOT [PRED_DIR NAME]..."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from fit_score_calibration import load_boxes, load_calib  # noqa: E402


def returns_in_label(pts, Tinv, box):
    """The returns (N x 3, sensor frame) inside a camera-frame label box (x, y, z, h, w, l, ry, ...) grown by 0.1 m
    on every side, and the box centre in the sensor frame."""
    x, y, z, h, w, l, ry = box[:7]
    c = Tinv @ np.array([x, y - h / 2, z, 1.0])
    yaw = -ry - math.pi / 2
    d = pts[:, :2] - c[:2]
    u = d[:, 0] * math.cos(yaw) + d[:, 1] * math.sin(yaw)
    v = -d[:, 0] * math.sin(yaw) + d[:, 1] * math.cos(yaw)
    inside = (np.abs(u) <= l / 2 + 0.1) & (np.abs(v) <= w / 2 + 0.1) & (np.abs(pts[:, 2] - c[2]) <= h / 2 + 0.1)
    return int(inside.sum()), c


def main():
    root = sys.argv[1].rstrip("/")
    root = root if root.endswith("training") else root + "/training"
    preds = list(zip(sys.argv[2::2], sys.argv[3::2]))
    bands = [(0, 30), (30, 48), (48, 56), (56, 64), (64, 72), (72, 80.5)]
    counts = [(0, 5), (5, 20), (20, 50), (50, 10 ** 9)]
    rows = []  # (range, returns, [found per pred])
    for seq in sorted(os.listdir(root + "/label_02")):
        s = seq[:4]
        Tinv = load_calib("%s/calib/%s.txt" % (root, s))  # camera -> sensor
        gt = load_boxes("%s/label_02/%s.txt" % (root, s), "Car", False)
        pr = [load_boxes("%s/%s.txt" % (p, s), "Car", False) for p, _ in preds]
        for frame, boxes in sorted(gt.items()):
            pts = np.fromfile("%s/velodyne/%s/%06d.bin" % (root, s, frame), dtype=np.float32).reshape(-1, 4)[:, :3]
            for box in boxes:
                x, _, z = box[:3]
                n, c = returns_in_label(pts, Tinv, box)
                found = [any(math.hypot(px - x, pz - z) < 2.0 for (px, _, pz, *_) in p.get(frame, []))
                         for p in pr]
                rows.append((math.hypot(c[0], c[1]), n, found))
    names = [n for _, n in preds]
    print("| range (m) | car labels | with >= 5 / >= 20 returns | " + " | ".join("found by %s" % n for n in names) + " |")
    print("| --- | --- | --- | " + " | ".join("---" for _ in names) + " |")
    for lo, hi in bands:
        sel = [r for r in rows if lo <= r[0] < hi]
        if not sel:
            continue
        n = len(sel)
        cells = ["%g-%g" % (lo, min(hi, 80)), str(n),
                 "%.1f / %.1f %%" % (100.0 * sum(r[1] >= 5 for r in sel) / n, 100.0 * sum(r[1] >= 20 for r in sel) / n)]
        cells += ["%.1f %%" % (100.0 * sum(r[2][k] for r in sel) / n) for k in range(len(names))]
        print("| " + " | ".join(cells) + " |")
    print()
    print("| returns in the box, cars beyond 48 m | car labels | " + " | ".join("found by %s" % n for n in names) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in names) + " |")
    for lo, hi in counts:
        sel = [r for r in rows if r[0] >= 48 and lo <= r[1] < hi]
        if sel:
            print("| %s | %d | " % ("%d-%d" % (lo, hi - 1) if hi < 10 ** 9 else ">= %d" % lo, len(sel)) +
                  " | ".join("%.1f %%" % (100.0 * sum(r[2][k] for r in sel) / len(sel)) for k in range(len(names))) + " |")
    total = len(rows)
    print("\n%d car labels; %.1f %% beyond 48 m; %.1f %% of all have fewer than 5 returns" %
          (total, 100.0 * sum(r[0] >= 48 for r in rows) / total, 100.0 * sum(r[1] < 5 for r in rows) / total))


if __name__ == "__main__":
    main()
