#!/usr/bin/env python3
"""What IntraRM's radius graph has to work with: over a `ret3d detect` result and its labels, how many
neighbours a detected box has within each radius (IntraRM links boxes whose BEV centres are closer than r), and how
far the detected boxes are from the objects they found (centre error, heading error), per class.

Usage: scripts/experiments/intra_graph_stats.py --gt DATA --pred PRED [--radii 1 2 4] [--min-score 0]
DATA is a KITTI tracking layout (training/label_02/SSSS.txt), PRED a `ret3d detect` output folder (SSSS.txt, the
same format with a score). Boxes are compared in the bird's-eye view of the camera frame (x, z).
"""
import argparse
import glob
import math
import os

import numpy as np

CLASSES = ("Car", "Pedestrian", "Cyclist")


def read(path, min_score=None):
    """tracking-format lines -> {frame: [(class, x, z, heading, score)]}"""
    frames = {}
    if not os.path.exists(path):
        return frames
    for line in open(path):
        t = line.split()
        if len(t) < 17 or t[2] not in CLASSES:
            continue
        score = float(t[17]) if len(t) > 17 else 1.0
        if min_score is not None and score < min_score:
            continue
        frames.setdefault(int(t[0]), []).append((t[2], float(t[13]), float(t[15]), float(t[16]), score))
    return frames


def angle_diff(a, b):
    """|a - b| modulo pi (a box's heading and its reverse draw the same box), in [0, pi/2]."""
    d = abs((a - b) % math.pi)
    return min(d, math.pi - d)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gt", required=True)
    ap.add_argument("--pred", required=True)
    ap.add_argument("--radii", type=float, nargs="+", default=[1.0, 2.0, 4.0])
    ap.add_argument("--min-score", type=float, default=0.0)
    ap.add_argument("--match", type=float, default=2.0, help="a box within this of a label of its class found it (m)")
    a = ap.parse_args()
    labels_dir = os.path.join(a.gt, "training", "label_02")
    if not os.path.isdir(labels_dir):
        labels_dir = os.path.join(a.gt, "label_02")
    neighbours = {r: [] for r in a.radii}
    gt_neighbours = {r: [] for r in a.radii}
    centre = {c: [] for c in CLASSES}
    heading = {c: [] for c in CLASSES}
    boxes = 0
    for path in sorted(glob.glob(os.path.join(a.pred, "*.txt"))):
        seq = os.path.basename(path)
        pred = read(path, a.min_score)
        gt = read(os.path.join(labels_dir, seq))
        for f, bs in pred.items():
            xy = np.array([[b[1], b[2]] for b in bs])
            d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
            boxes += len(bs)
            for r in a.radii:
                neighbours[r].extend(((d < r).sum(1) - 1).tolist())
            g = gt.get(f, [])
            for b in bs:
                best, best_d = None, a.match
                for o in g:
                    if o[0] != b[0]:
                        continue
                    dd = math.hypot(o[1] - b[1], o[2] - b[2])
                    if dd < best_d:
                        best, best_d = o, dd
                if best is not None:
                    centre[b[0]].append(best_d)
                    heading[b[0]].append(math.degrees(angle_diff(best[3], b[3])))
        for f, g in gt.items():
            xy = np.array([[o[1], o[2]] for o in g])
            d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
            for r in a.radii:
                gt_neighbours[r].extend(((d < r).sum(1) - 1).tolist())
    print("%d detected boxes (score >= %.2f) in %s" % (boxes, a.min_score, a.pred))
    print("| radius | detected boxes with a neighbour | mean neighbours | labelled objects with a neighbour |")
    print("| --- | --- | --- | --- |")
    for r in a.radii:
        n, gn = np.array(neighbours[r]), np.array(gt_neighbours[r])
        print("| %.1f m | %.1f %% | %.2f | %.1f %% |" % (r, 100 * (n > 0).mean(), n.mean(), 100 * (gn > 0).mean()))
    print("| class | boxes that found a label | centre error median / p90 (m) | heading error median / p90 (deg) |")
    print("| --- | --- | --- | --- |")
    for c in CLASSES:
        if not centre[c]:
            continue
        ce, he = np.array(centre[c]), np.array(heading[c])
        print("| %s | %d | %.2f / %.2f | %.1f / %.1f |" % (c, len(ce), np.median(ce), np.percentile(ce, 90),
                                                          np.median(he), np.percentile(he, 90)))


if __name__ == "__main__":
    main()
