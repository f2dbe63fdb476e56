#!/usr/bin/env python3
"""Per object, what detectors put on the labelled pedestrians and cyclists of the six real KITTI frames.

For each labelled Pedestrian and Cyclist (KITTI object label_2), the prediction boxes of each given folder (KITTI
result files, e.g. scripts/experiments/real_scans.sh's OUT/pred) whose centre lies within 1 m of it in the ground
plane: class, score, centre distance. A diagnosis of which objects a detector finds and as what; AP is `ret3d eval`'s.
Usage: real_matches.py PRED_DIR [PRED_DIR...]   (labels from $RET3D_SHARED_DATA or ../shared/data)
"""
import glob
import math
import os
import sys

DATA = os.environ.get("RET3D_SHARED_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))
LABELS = os.path.join(DATA, "kitti_object", "training", "label_2")


def read(path):
    """(type, x, z, score) per line of a KITTI label or result file; camera frame x (right) and z (forward)."""
    out = []
    if not os.path.exists(path):
        return out
    for line in open(path):
        p = line.split()
        if len(p) < 15:
            continue
        out.append((p[0], float(p[11]), float(p[13]), float(p[15]) if len(p) > 15 else 1.0))
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    if not os.path.isdir(LABELS):
        sys.exit("real_matches.py: no labels at %s (set RET3D_SHARED_DATA)" % LABELS)
    for pred_dir in sys.argv[1:]:
        print("==", pred_dir)
        for label_file in sorted(glob.glob(os.path.join(LABELS, "*.txt"))):
            frame = os.path.basename(label_file)
            preds = read(os.path.join(pred_dir, frame))
            for t, x, z, _ in read(label_file):
                if t not in ("Pedestrian", "Cyclist"):
                    continue
                near = sorted((math.hypot(px - x, pz - z), pt, ps) for pt, px, pz, ps in preds
                              if math.hypot(px - x, pz - z) < 1.0)
                found = " ".join("%s %.2f at %.2f m" % (pt, ps, d) for d, pt, ps in near[:3]) or "-"
                print("%s %-10s %3.0f m away: %s" % (frame[:-4], t, math.hypot(x, z), found))


if __name__ == "__main__":
    main()
