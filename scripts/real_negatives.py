#!/usr/bin/python3
"""Labels for teaching real backgrounds (walls, poles, vegetation) to the detector from unlabelled real scans.

Input: an object-layout folder ROOT/training/{velodyne,calib} of real scans, and the detector's boxes on them at a low
score threshold (`ret3d detect --data ROOT --stages base --score-threshold 0.05 --out PRED`). Output: ROOT/training/
label_2, one file per scan, for `ret3d train detector --data ROOT --labels-cover all`:

- a pedestrian or cyclist box embedded in a larger structure (returns all along its sides: a wall, a hedge, a fence, a
  trunk in foliage) or under returns higher than any such object (a tree, a pole with a sign, a building's edge) is
  left out: its place is taught as background, which is what the detector gets wrong on real scans;
- every other box becomes a DontCare box (grown by --grow m): it may be a real object the detector half sees, and
  an unlabelled object must not be taught as background (the training masks DontCare boxes);
- objects: only cars the detector is sure of (score >= --car-score, at least --car-points returns inside; their
  heading fitted to the returns' outline by the detector's point refinement) are written as Car, the rest of the
  objects come from the simulated folders trained beside, and from ground-truth sampling, which pastes them into
  these real scenes;
- tracked cars (--tracks, consecutive scans only): a car that the pipeline tracked over many frames with a high mean
  score (`ret3d autolabel`'s smoothed tracks, --track-frames, --track-score) is a Car label in every frame of its
  track whose box holds --track-points returns, far and partly hidden frames included; a single frame's confident
  box is never enough. The detector's boxes on a tracked car are neither background nor DontCare; the boxes of
  shorter or weaker car tracks are DontCare.

Usage: scripts/real_negatives.py ROOT PRED [--grow 0.3] [--min-score 0.1] [--car-score 1.1] [--car-points 30]
       [--tracks LABEL_02_FILE --tracks-first-frame N]
Prints how many boxes per class became background, DontCare and labels.
"""
import argparse
import glob
import math
import os
import sys

import numpy as np

from fit_score_calibration import load_calib  # camera (rectified) -> LiDAR, from a KITTI calib file


def camera_box_to_velo(box, cam_to_velo):
    """(h, w, l, x, y, z, ry) in camera coordinates -> (x, y, z_bottom, l, w, h, yaw) in the LiDAR frame."""
    h, w, l, x, y, z, ry = box
    c = cam_to_velo @ np.array([x, y, z, 1.0])
    return (c[0], c[1], c[2], l, w, h, -ry - math.pi / 2)


def read_results(path):
    """KITTI result lines -> [(line, class, score, (h, w, l, x, y, z, ry) in camera coordinates)]."""
    out = []
    if not os.path.exists(path):
        return out
    for line in open(path):
        f = line.split()
        if len(f) >= 16:
            out.append((line, f[0], float(f[15]), [float(v) for v in f[8:15]]))
    return out


def local_frame(pts, x, y, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = pts[:, 0] - x, pts[:, 1] - y
    return c * dx + s * dy, -s * dx + c * dy


def returns_in(pts, b):
    """Returns inside the box from 0.3 m above its bottom (the ground left out)."""
    cls, score, x, y, zb, l, w, h, yaw = b
    near = pts[(np.abs(pts[:, 0] - x) < l) & (np.abs(pts[:, 1] - y) < l)]
    u, v = local_frame(near, x, y, yaw)
    return int(((np.abs(u) <= l / 2) & (np.abs(v) <= w / 2) & (near[:, 2] > zb + 0.3) & (near[:, 2] < zb + h)).sum())


def label_line(kind, h, w, l, x, y, z, ry):
    """A KITTI label line of a box in camera coordinates (no 2D box, alpha unknown)."""
    return "%s 0.00 0 -10 0 0 0 0 %.3f %.3f %.3f %.3f %.3f %.3f %.4f\n" % (kind, h, w, l, x, y, z, ry)


def read_tracks(path, first_frame, min_frames, min_score):
    """`ret3d autolabel` KITTI tracking labels -> {object frame: [(kept, h, w, l, x, y, z, ry)]} of Car tracks.

    kept: the track has at least min_frames frames and a mean score of at least min_score (its last column)."""
    frames = {}
    for f in (line.split() for line in open(path)):
        if len(f) >= 17 and f[2] == "Car":
            frames.setdefault(int(f[1]), []).append(f)
    out = {}
    for track in frames.values():
        kept = len(track) >= min_frames and float(track[0][17] if len(track[0]) > 17 else 0.0) >= min_score
        for f in track:
            box = (kept,) + tuple(float(v) for v in f[10:17])
            out.setdefault("%06d" % (first_frame + int(f[0])), []).append(box)
    return out


def embedded_in_structure(pts, b):
    """True when a small-object box stands in a wall, hedge or under a tree rather than in free space."""
    cls, score, x, y, zb, l, w, h, yaw = b
    near = pts[(np.abs(pts[:, 0] - x) < 4) & (np.abs(pts[:, 1] - y) < 4)]
    if len(near) == 0:
        return False
    u, v = local_frame(near, x, y, yaw)
    ground = np.percentile(near[:, 2], 5)
    above = near[:, 2] - ground
    inside = (np.abs(u) <= l / 2) & (np.abs(v) <= w / 2)
    body = inside & (above > 0.3) & (above < 2.2)
    tall = inside & (above > 2.6)
    # The band 0.3-1.0 m beyond the box's sides: free space around a person or a cyclist, a wall or hedge beside a
    # box cut out of it.
    band = (np.abs(u) <= l / 2 + 1.0) & (np.abs(v) <= w / 2 + 1.0) & ~((np.abs(u) <= l / 2 + 0.3) & (np.abs(v) <= w / 2 + 0.3))
    band &= (above > 0.3) & (above < 2.2)
    n_body, n_tall, n_band = int(body.sum()), int(tall.sum()), int(band.sum())
    # Fewer than five returns: nothing to see at the place (behind a wall, in a gap of the scan).
    return n_body < 5 or n_tall >= 5 or n_band > max(8, 1.5 * n_body)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root")
    ap.add_argument("pred")
    ap.add_argument("--grow", type=float, default=0.3)
    ap.add_argument("--min-score", type=float, default=0.1,
                    help="boxes scored lower are background too (the detector already calls them so)")
    ap.add_argument("--car-score", type=float, default=1.1, help="cars scored this or more are labels (default: none)")
    ap.add_argument("--car-points", type=int, default=30, help="... with at least this many returns in the box")
    ap.add_argument("--tracks", help="`ret3d autolabel` label_02 file of the consecutive scans among ROOT's frames")
    ap.add_argument("--tracks-first-frame", type=int, default=0, help="ROOT's frame number of the tracks' frame 0")
    ap.add_argument("--track-frames", type=int, default=8, help="a car track is a label from this many frames")
    ap.add_argument("--track-score", type=float, default=0.5, help="... with at least this mean score")
    ap.add_argument("--track-points", type=int, default=10, help="... in its frames with this many returns")
    ap.add_argument("--debug-out", help="also write the boxes left as background here (KITTI result files)")
    a = ap.parse_args()
    tracks = read_tracks(a.tracks, a.tracks_first_frame, a.track_frames, a.track_score) if a.tracks else {}
    tr = os.path.join(a.root, "training") if os.path.isdir(os.path.join(a.root, "training")) else a.root
    scans = sorted(glob.glob(os.path.join(tr, "velodyne", "*.bin")))
    if not scans:
        sys.exit("real_negatives.py: no scans in %s/velodyne" % tr)
    os.makedirs(os.path.join(tr, "label_2"), exist_ok=True)
    counts = {}
    for scan in scans:
        frame = os.path.splitext(os.path.basename(scan))[0]
        cam_to_velo = load_calib(os.path.join(tr, "calib", frame + ".txt"))
        pts = np.fromfile(scan, dtype=np.float32).reshape(-1, 4)[:, :3].astype(np.float64)
        lines = []
        tracked = []  # (x, y, reach) of this frame's tracked cars in the LiDAR frame
        for kept, *cam in tracks.get(frame, []):
            x, y, zb, l, w, h, yaw = camera_box_to_velo(cam, cam_to_velo)
            tracked.append((x, y, max(l, w) / 2 + 0.5))
            label = kept and returns_in(pts, ("Car", 1.0, x, y, zb, l, w, h, yaw)) >= a.track_points
            key = ("Car", "tracked" if label else "track DontCare")
            counts[key] = counts.get(key, 0) + 1
            hc, wc, lc, xc, yc, zc, ry = cam
            if label:
                lines.append(label_line("Car", hc, wc, lc, xc, yc, zc, ry))
            else:
                lines.append(label_line("DontCare", hc + 0.2, wc + 2 * a.grow, lc + 2 * a.grow, xc, yc, zc, ry))
        for line, cls, score, cam in read_results(os.path.join(a.pred, frame + ".txt")):
            b = (cls, score) + camera_box_to_velo(cam, cam_to_velo)  # (class, score, x, y, z_bottom, l, w, h, yaw)
            if any(math.hypot(b[2] - x, b[3] - y) < reach for x, y, reach in tracked):
                continue  # on a tracked car: its label or DontCare is written above
            background = score < a.min_score or (cls in ("Pedestrian", "Cyclist") and embedded_in_structure(pts, b))
            key = (cls, "background" if background else "DontCare")
            counts[key] = counts.get(key, 0) + 1
            if background:
                if a.debug_out:
                    os.makedirs(a.debug_out, exist_ok=True)
                    with open(os.path.join(a.debug_out, frame + ".txt"), "a") as f:
                        f.write(line)
                continue
            h, w, l, x, y, z, ry = cam
            if cls == "Car" and score >= a.car_score and returns_in(pts, b) >= a.car_points:
                counts[(cls, "label")] = counts.get((cls, "label"), 0) + 1
                lines.append(label_line("Car", h, w, l, x, y, z, ry))
                continue
            lines.append(label_line("DontCare", h + 0.2, w + 2 * a.grow, l + 2 * a.grow, x, y, z, ry))
        with open(os.path.join(tr, "label_2", frame + ".txt"), "w") as f:
            f.writelines(lines)
    for k in sorted(counts):
        print("%-10s %-10s %6d" % (k[0], k[1], counts[k]))
    print("%d scans" % len(scans))


if __name__ == "__main__":
    main()
