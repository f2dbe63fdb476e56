#!/usr/bin/env python3
"""Summary table of scripts/experiments/loso_intra_kitti.sh: per fold KITTI 3D AP R40 moderate of the base PointRCNN
boxes, + the fold's IntraRM and + the shipped intra_rm.pt, label counts, and per class the mean / std / sign count of
the gain over the folds that have moderate ground truth of that class."""
import argparse
import datetime
import json
import math
import os
import re

CLASSES = ("Car", "Pedestrian", "Cyclist")
IOU = {"Car": "0.7", "Pedestrian": "0.5", "Cyclist": "0.5"}


def expand(spec):
    seqs = []
    for part in spec.split(","):
        if "-" in part:
            a, b = part.split("-")
            seqs += list(range(int(a), int(b) + 1))
        else:
            seqs.append(int(part))
    return seqs


def metrics(folder):
    with open(os.path.join(folder, "metrics.json")) as f:
        return json.load(f)


def ap(m, cls):
    return m["kitti.%s.3d.R40.moderate" % cls]


def label_counts(labels, seqs):
    """Labelled objects (boxes over all frames) and tracks per class in these sequences."""
    objects = {c: 0 for c in CLASSES}
    tracks = {c: 0 for c in CLASSES}
    for s in seqs:
        ids = {c: set() for c in CLASSES}
        with open(os.path.join(labels, "%04d.txt" % s)) as f:
            for line in f:
                cols = line.split()
                if len(cols) > 2 and cols[2] in CLASSES:
                    objects[cols[2]] += 1
                    ids[cols[2]].add(cols[1])
        for c in CLASSES:
            tracks[c] += len(ids[c])
    return objects, tracks


def stats(gains):
    """mean, sample std, standard error, positive count of a list of gains."""
    n = len(gains)
    if n == 0:
        return None
    mean = sum(gains) / n
    std = math.sqrt(sum((g - mean) ** 2 for g in gains) / (n - 1)) if n > 1 else float("nan")
    return mean, std, std / math.sqrt(n), sum(1 for g in gains if g > 0), n


def stats_row(name, gains):
    cells = []
    for c in CLASSES:
        s = stats(gains[c])
        if s is None:
            cells.append("- | - | - | - | -")
            continue
        mean, std, se, pos, n = s
        if n < 2:
            cells.append("%+.2f | - | - | - | %d/%d" % (mean, pos, n))
        else:
            cells.append("%+.2f | %.2f | %.2f | %+.2f | %d/%d" % (mean, std, se, mean - se, pos, n))
    return "| %s | %s |" % (name, " | ".join(cells))


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", required=True, help="out/loso_intra_kitti")
    p.add_argument("--pooled", required=True, help="folder with eval_{base,intra,shipped} of all held-out predictions")
    p.add_argument("--labels", required=True, help="KITTI tracking label_02 folder")
    p.add_argument("--shipped-train", default="1-15", help="sequences the shipped model was trained on")
    p.add_argument("--summary", required=True, help="markdown file to write")
    p.add_argument("--config", required=True, help="the IntraRM YAML the folds were trained with")
    p.add_argument("--folds", nargs="+", required=True, help="fold sequence specs, e.g. 1-4 5-8")
    a = p.parse_args()
    shipped_train = set(expand(a.shipped_train))
    with open(a.config) as f:
        yaml_text = f.read()
    epochs, seed = (re.search(r"^\s*%s:\s*(\S+)" % k, yaml_text, re.M) for k in ("epochs", "seed"))
    config = "%s (%s epochs, seed %s)" % (os.path.relpath(a.config), epochs.group(1) if epochs else "?",
                                         seed.group(1) if seed else "?")

    rows, shipped_rows = [], []
    gains = {c: [] for c in CLASSES}
    gains_shipped = {c: [] for c in CLASSES}      # folds the shipped model never saw
    gains_shipped_all = {c: [] for c in CLASSES}  # every fold, its training data included
    train_secs = []
    for fold in a.folds:
        d = os.path.join(a.out, "fold_" + fold.replace(",", "_"))
        base, intra, shipped = (metrics(os.path.join(d, "eval_" + n)) for n in ("base", "intra", "shipped"))
        with open(os.path.join(d, "train.secs")) as f:
            train_secs.append(int(f.read()))
        seqs = expand(fold)
        objects, tracks = label_counts(a.labels, seqs)
        seen = set(seqs) & shipped_train
        mark = "training data" if seen == set(seqs) else ("partly training data" if seen else "held out")
        cells, scells = [], []
        for c in CLASSES:
            moderate = int(base["count.kitti.%s.gt.moderate" % c])
            counts = "%d/%d/%d" % (objects[c], tracks[c], moderate)
            if moderate == 0:
                cells.append("- | - | - | %s" % counts)
                scells.append("-")
                continue
            g = ap(intra, c) - ap(base, c)
            gs = ap(shipped, c) - ap(base, c)
            gains[c].append(g)
            gains_shipped_all[c].append(gs)
            if not seen:
                gains_shipped[c].append(gs)
            cells.append("%.2f | %.2f | %+.2f | %s" % (ap(base, c), ap(intra, c), g, counts))
            scells.append("%.2f (%+.2f)" % (ap(shipped, c), gs))
        name = "%04d" % seqs[0] if len(seqs) == 1 else "%04d-%04d" % (seqs[0], seqs[-1]) \
            if seqs == list(range(seqs[0], seqs[-1] + 1)) else fold
        rows.append("| %s | %s |" % (name, " | ".join(cells)))
        shipped_rows.append("| %s | %s | %s |" % (name, " | ".join(scells), mark))

    pooled = {n: metrics(os.path.join(a.pooled, "eval_" + n)) for n in ("base", "intra", "shipped")}
    out = []
    out.append("# IntraRM on PointRCNN boxes: cross-validation over KITTI tracking 0001-0020\n")
    out.append("`scripts/experiments/loso_intra_kitti.sh` (%s UTC). %d folds; each fold's IntraRM trained on the "
               "other sequences of 0001-0020 with %s; %d-%d s per training, 1 thread. "
               "KITTI 3D AP R40 moderate (Car @0.7, Pedestrian / Cyclist @0.5) from `ret3d eval`'s metrics.json. "
               "Counts: labelled objects (boxes over all frames) / tracks / moderate ground-truth boxes the AP counts. "
               "A class without moderate ground truth in a fold is left out of that fold's statistics.\n"
               % (datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), len(a.folds), config, min(train_secs),
                  max(train_secs)))
    head = " | ".join("%s base | %s +IntraRM | gain | %s obj/trk/mod" % (c[:3], c[:3], c[:3]) for c in CLASSES)
    out.append("## Per fold (IntraRM trained without the fold)\n")
    out.append("| held out | %s |" % head)
    out.append("|" + " --- |" * (1 + 4 * len(CLASSES)))
    out += rows
    out.append("\n## Gain per class over the folds (IntraRM - base, AP points)\n")
    out.append("Columns per class: mean | std | standard error | mean - SE | folds with gain > 0.\n")
    out.append("| | %s |" % " | ".join("%s mean | std | SE | mean-SE | >0" % c[:3] for c in CLASSES))
    out.append("|" + " --- |" * (1 + 5 * len(CLASSES)))
    out.append(stats_row("fold IntraRM", gains))
    out.append(stats_row("shipped, folds it never saw", gains_shipped))
    out.append(stats_row("shipped, all folds (incl. its training data)", gains_shipped_all))
    out.append("\n## All held-out predictions evaluated at once\n")
    out.append("Each sequence scored by the fold model that did not see it, all folds evaluated together "
               "(the shipped model row includes its training sequences %s). The fold IntraRM row ranks boxes scored by "
               "different models against each other, so it also pays for their calibration differing; the per-fold "
               "table is the cleaner measure.\n" % a.shipped_train)
    out.append("| | %s |" % " | ".join(CLASSES))
    out.append("| --- | --- | --- | --- |")
    for n, label in (("base", "PointRCNN (base)"), ("intra", "+ fold IntraRM"), ("shipped", "+ shipped intra_rm.pt")):
        out.append("| %s | %s |" % (label, " | ".join("%.2f" % ap(pooled[n], c) for c in CLASSES)))
    out.append("| gain, fold IntraRM | %s |" % " | ".join(
        "%+.2f" % (ap(pooled["intra"], c) - ap(pooled["base"], c)) for c in CLASSES))
    out.append("\n## Shipped models/kitti_pointrcnn/intra_rm.pt per fold: AP (gain over base)\n")
    out.append("| held out | %s | for the shipped model |" % " | ".join(CLASSES))
    out.append("| --- | --- | --- | --- | --- |")
    out += shipped_rows
    with open(a.summary, "w") as f:
        f.write("\n".join(out) + "\n")
    print("\n".join(out))


if __name__ == "__main__":
    main()
