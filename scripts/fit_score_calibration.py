#!/usr/bin/env python3
"""Fits the detector's score calibration (point_refine.score_calibration, include/ret3d/detector/point_refine.h).

Reads the boxes of one class that `ret3d detect --stages base` wrote for a labelled KITTI tracking-layout folder (run
with the calibration off), counts the returns that hold each box exactly as the detector does, and fits a logistic
regression of "the box overlaps a true one by at least --iou in 3D" on the features
  [1, logit(score), log(1 + n), r / 40, log(1 + n) r / 40, logit(score) log(1 + n), a, a^2, e]
(n returns, r range, a = |sin(heading - bearing)|, e the returns' median distance to the nearest face).
Prints the weights as the YAML line to paste under inference.point_refine.score_calibration.

  scripts/fit_score_calibration.py --gt data/sim_relation_urban --pred out/calib/pred [--class Car] [--iou 0.7]
      [--no-shape]
"""
import argparse
import glob
import math
import os
import sys

import numpy as np


def load_calib(path):
    calib = {}
    for line in open(path):
        if ':' in line:
            key, values = line.split(':', 1)
            calib[key] = np.array([float(v) for v in values.split()])
    tr = np.vstack([calib['Tr_velo_to_cam'].reshape(3, 4), [0, 0, 0, 1]])
    r0 = np.eye(4)
    r0[:3, :3] = calib['R0_rect'].reshape(3, 3)
    return np.linalg.inv(r0 @ tr)  # camera (rectified) -> LiDAR


def load_boxes(path, cls, with_score):
    """frame -> list of (x, y, z, h, w, l, ry, score) in the camera frame (KITTI tracking lines)."""
    boxes = {}
    if not os.path.exists(path):
        return boxes
    for line in open(path):
        t = line.split()
        if len(t) < 17 or t[2] != cls:
            continue
        h, w, l, x, y, z, ry = map(float, t[10:17])
        score = float(t[17]) if with_score and len(t) > 17 else 1.0
        boxes.setdefault(int(t[0]), []).append((x, y, z, h, w, l, ry, score))
    return boxes


def footprint(b):
    """Corners of a camera-frame box on the ground plane (x, z), counter-clockwise."""
    x, _, z, _, w, l, ry = b[:7]
    c, s = math.cos(ry), math.sin(ry)
    pts = [(x + dl * c + dw * s, z - dl * s + dw * c) for dl, dw in ((l / 2, w / 2), (l / 2, -w / 2),
                                                                     (-l / 2, -w / 2), (-l / 2, w / 2))]
    area2 = sum(pts[i][0] * pts[(i + 1) % 4][1] - pts[(i + 1) % 4][0] * pts[i][1] for i in range(4))
    return pts if area2 > 0 else pts[::-1]


def polygon_area(p):
    return abs(sum(p[i][0] * p[(i + 1) % len(p)][1] - p[(i + 1) % len(p)][0] * p[i][1] for i in range(len(p)))) / 2


def overlap_area(a, b):
    """Area of the intersection of two convex counter-clockwise polygons (Sutherland-Hodgman)."""
    def inside(p, e0, e1):
        return (e1[0] - e0[0]) * (p[1] - e0[1]) - (e1[1] - e0[1]) * (p[0] - e0[0]) >= 0

    def cross(p, q, e0, e1):
        d = (p[0] - q[0]) * (e0[1] - e1[1]) - (p[1] - q[1]) * (e0[0] - e1[0])
        if abs(d) < 1e-12:
            return q
        t = ((p[0] - e0[0]) * (e0[1] - e1[1]) - (p[1] - e0[1]) * (e0[0] - e1[0])) / d
        return (p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]))

    out = a
    for i in range(len(b)):
        e0, e1 = b[i], b[(i + 1) % len(b)]
        if not out:
            break
        src, out, prev = out, [], out[-1]
        for p in src:
            if inside(p, e0, e1):
                if not inside(prev, e0, e1):
                    out.append(cross(prev, p, e0, e1))
                out.append(p)
            elif inside(prev, e0, e1):
                out.append(cross(prev, p, e0, e1))
            prev = p
    return polygon_area(out) if len(out) >= 3 else 0.0


def iou_3d(a, b):
    inter = overlap_area(footprint(a), footprint(b))
    # Camera y points down; a box spans [y - h, y].
    dy = max(0.0, min(a[1], b[1]) - max(a[1] - a[3], b[1] - b[3]))
    v = inter * dy
    return v / (a[3] * a[4] * a[5] + b[3] * b[4] * b[5] - v)


MAX_RESIDUAL = 0.5  # PointRefineOptions::kMaxResidual


def returns_holding(points, b, cam_to_lidar, margin, clearance):
    """n, range, aspect and residual as the detector computes them: the returns within the footprint grown by
    margin, from clearance above the bottom to margin above the top (LiDAR frame)."""
    x, y, z, h, w, l, ry = b[:7]
    c = cam_to_lidar @ np.array([x, y, z, 1.0])  # the centre of the bottom face
    yaw = -ry - math.pi / 2
    dx, dy = points[:, 0] - c[0], points[:, 1] - c[1]
    u = dx * math.cos(yaw) + dy * math.sin(yaw)
    v = -dx * math.sin(yaw) + dy * math.cos(yaw)
    inside = ((np.abs(u) < l / 2 + margin) & (np.abs(v) < w / 2 + margin) & (points[:, 2] > c[2] + clearance) &
              (points[:, 2] < c[2] + h + margin))
    n = int(inside.sum())
    residual = MAX_RESIDUAL
    if n >= 3:
        d = np.sort(np.minimum(np.abs(np.abs(u[inside]) - l / 2), np.abs(np.abs(v[inside]) - w / 2)))
        residual = min(residual, float(d[(n - 1) // 2]))
    aspect = abs(math.sin(yaw - math.atan2(c[1], c[0])))
    return n, math.hypot(c[0], c[1]), aspect, residual


def features(score, n, r, aspect, residual):
    s = min(max(score, 1e-4), 1 - 1e-4)
    logit, log_n, rr = math.log(s / (1 - s)), math.log1p(n), r / 40.0
    return [1.0, logit, log_n, rr, log_n * rr, logit * log_n, aspect, aspect * aspect, residual]


def fit_logistic(x, y, l2=1e-3, iterations=50):
    w = np.zeros(x.shape[1])
    for _ in range(iterations):
        p = 1 / (1 + np.exp(-x @ w))
        grad = x.T @ (p - y) + l2 * w
        hess = (x * (p * (1 - p))[:, None]).T @ x + l2 * np.eye(len(w))
        w -= np.linalg.solve(hess, grad)
    return w


def log_loss(p, y):
    p = np.clip(p, 1e-6, 1 - 1e-6)
    return float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--gt', required=True, help='labelled KITTI tracking-layout folder (with training/ or not)')
    ap.add_argument('--pred', required=True, help='ret3d detect output folder (one file per sequence)')
    ap.add_argument('--class', dest='cls', default='Car')
    ap.add_argument('--iou', type=float, default=0.7, help='3D IoU a box must reach to count as good')
    ap.add_argument('--margin', type=float, default=0.3, help='point_refine.margin of the detector config')
    ap.add_argument('--ground-clearance', type=float, default=0.3, help='point_refine.ground_clearance')
    ap.add_argument('--no-shape', action='store_true',
                    help='fit only the first six weights (score, returns, range); a, a^2 and e get 0')
    args = ap.parse_args()
    root = os.path.join(args.gt, 'training') if os.path.isdir(os.path.join(args.gt, 'training')) else args.gt
    files = sorted(glob.glob(os.path.join(args.pred, '*.txt')))
    if not files:
        sys.exit('fit_score_calibration: no prediction files in %s' % args.pred)
    rows, labels = [], []
    for f in files:
        seq = os.path.basename(f)[:-4]
        cam_to_lidar = load_calib(os.path.join(root, 'calib', seq + '.txt'))
        truth = load_boxes(os.path.join(root, 'label_02', seq + '.txt'), args.cls, False)
        for frame, boxes in sorted(load_boxes(f, args.cls, True).items()):
            scan = os.path.join(root, 'velodyne', seq, '%06d.bin' % frame)
            points = np.fromfile(scan, dtype=np.float32).reshape(-1, 4)
            for b in boxes:
                best = max([iou_3d(g, b) for g in truth.get(frame, []) if math.hypot(g[0] - b[0], g[2] - b[2]) < 5],
                           default=0.0)
                rows.append(features(b[7], *returns_holding(points, b, cam_to_lidar, args.margin, args.ground_clearance)))
                labels.append(1.0 if best >= args.iou else 0.0)
    x, y = np.array(rows), np.array(labels)
    if len(y) < 50 or y.min() == y.max():
        sys.exit('fit_score_calibration: %d boxes of %s, %d good: too few to fit' % (len(y), args.cls, int(y.sum())))
    used = 6 if args.no_shape else x.shape[1]
    w = np.zeros(x.shape[1])
    w[:used] = fit_logistic(x[:, :used], y)
    before = 1 / (1 + np.exp(-x[:, 1]))
    after = 1 / (1 + np.exp(-x @ w))
    print('%d %s boxes from %d sequences, %.1f %% with 3D IoU >= %.2f' % (len(y), args.cls, len(files),
                                                                          100 * y.mean(), args.iou))
    print('log loss of the scores: %.4f as detected, %.4f calibrated' % (log_loss(before, y), log_loss(after, y)))
    print('score_calibration: {%s: [%s]}' % (args.cls, ', '.join('%.4f' % v for v in w)))


if __name__ == '__main__':
    main()
