#!/usr/bin/python3
"""What Car MOTA a detector that sees only cars with enough returns could reach at best (the bar of 75 over
the labels' 80 m). Writes, for each minimum return count K, a KITTI tracking result folder holding exactly the car
labels whose box (grown by 0.1 m) holds at least K LiDAR returns, with their true track ids and score 1: a perfect
detector and tracker for those cars, and blind to the others. `ret3d eval --metric mot` on each gives the bound.
  scripts/experiments/oracle_tracks.py GT_ROOT OUT_DIR K [K...]   (writes OUT_DIR/min<K>/SSSS.txt)"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from far_cars import returns_in_label  # noqa: E402
from fit_score_calibration import load_calib  # noqa: E402


def main():
    root = sys.argv[1].rstrip("/")
    root = root if root.endswith("training") else root + "/training"
    out, ks = sys.argv[2], [int(k) for k in sys.argv[3:]]
    total = {k: 0 for k in ks}
    labels = 0
    for name in sorted(os.listdir(root + "/label_02")):
        s = name[:4]
        Tinv = load_calib("%s/calib/%s.txt" % (root, s))
        by_frame = {}
        for line in open("%s/label_02/%s" % (root, name)):
            f = line.split()
            if len(f) >= 17 and f[2] == "Car":
                by_frame.setdefault(int(f[0]), []).append(f)
        kept = {k: [] for k in ks}
        for frame, rows in sorted(by_frame.items()):
            pts = np.fromfile("%s/velodyne/%s/%06d.bin" % (root, s, frame), dtype=np.float32).reshape(-1, 4)[:, :3]
            for f in rows:
                h, w, l, x, y, z, ry = (float(v) for v in f[10:17])
                n = returns_in_label(pts, Tinv, (x, y, z, h, w, l, ry))[0]
                labels += 1
                for k in ks:
                    if n >= k:
                        kept[k].append(" ".join(f[:17]) + " 1.0\n")
        for k in ks:
            os.makedirs("%s/min%d" % (out, k), exist_ok=True)
            with open("%s/min%d/%s.txt" % (out, k, s), "w") as o:
                o.writelines(kept[k])
            total[k] += len(kept[k])
    for k in ks:
        print("min %d returns: %d of %d car labels (%.1f %%)" % (k, total[k], labels, 100.0 * total[k] / labels))


if __name__ == "__main__":
    main()
