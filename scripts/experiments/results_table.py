#!/usr/bin/env python3
"""Markdown tables of the simulated ablations (scripts/experiments/ablate_{intra,inter}_sim.sh) from their held-out
evaluations (out/heldout/NAME/eval/metrics.json), printed and written into docs/RESULTS.md between the table's markers.

  results_table.py intra OUT_DIR CONFIG...   # rows: base, then base + each IntraRM
  results_table.py inter OUT_DIR NAME...     # rows: + IntraRM + tracker, then + each InterRM (history, encoding)
  results_table.py table3 INTER_NAME         # Ret3D Table 3 analogue: base, + IntraRM, + tracker, + InterRM
"""
import json
import os
import re
import sys

CLASSES = ("Car", "Pedestrian", "Cyclist")
RESULTS = "docs/RESULTS.md"


def metrics(name):
    return json.load(open("out/heldout/%s/eval/metrics.json" % name))


def ap_cells(m):
    return ["%.2f" % m["kitti.%s.3d.R40.moderate" % c] for c in CLASSES] + [
        "%.2f" % m["waymo.mean.L2.AP"], "%.2f" % m["waymo.mean.L2.APH"]]


def train_seconds(log, marker):
    """Wall time of a training from its log line '<marker> N epochs in S s; ...' ('' when absent)."""
    if not os.path.exists(log):
        return ""
    for line in open(log):
        if marker in line:
            return "%.0f" % float(line.split(" in ")[1].split(" s")[0])
    return ""


def shipped_history():
    """max_history of config/relation/inter_lwd3d.yaml, the shipped InterRM's config."""
    for line in open("config/relation/inter_lwd3d.yaml"):
        m = re.match(r"\s*max_history:\s*(\d+)", line)
        if m:
            return int(m.group(1))
    raise SystemExit("config/relation/inter_lwd3d.yaml: no max_history")


def write_between(key, lines):
    text = open(RESULTS).read()
    begin, end = "<!-- %s:begin -->" % key, "<!-- %s:end -->" % key
    if begin not in text or end not in text:
        print("(no %s markers in %s: table not written)" % (key, RESULTS))
        return
    a, b = text.index(begin) + len(begin), text.index(end)
    open(RESULTS, "w").write(text[:a] + "\n" + "\n".join(lines) + "\n" + text[b:])
    print("written to %s (%s)" % (RESULTS, key))


def intra_table(out, configs):
    what = {"base": "base detector alone", "intra_lwd3d": "r 2 m, m 4 (the paper's m)",
            "intra_lwd3d_no_edge": "no edges (r 2 m, m 4)", "intra_lwd3d_r1": "r 1 m, m 4",
            "intra_lwd3d_r4": "r 4 m, m 4", "intra_lwd3d_m1": "r 2 m, m 1 (shipped)", "intra_lwd3d_m2": "r 2 m, m 2",
            "intra_lwd3d_m6": "r 2 m, m 6"}
    lines = ["| configuration | graph | Car 3D @0.7 | Ped 3D @0.5 | Cyc 3D @0.5 | L2 mAP | L2 mAPH | train s |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in ["base"] + configs:
        secs = "" if r == "base" else train_seconds("%s/%s.train.log" % (out, r), "IntraRM trained:")
        lines.append("| " + " | ".join([r, what.get(r, "")] + ap_cells(metrics(r)) + [secs]) + " |")
    print("\n".join(lines))
    write_between("intra-sim-ablation", lines)


def inter_row(out, name, label):
    m = metrics("sim_" + name)
    cost = ""
    bench = "%s/%s.bench.json" % (out, name)
    if os.path.exists(bench):
        b = json.load(open(bench))
        if "total_50_spread" in b:
            cost = "%.2f / %.2f" % (b["total_50_spread"]["median_ms"], b["total_50_spread"]["p95_ms"])
    return ("| " + " | ".join([label] + ap_cells(m) + ["%.1f" % m["mot.Car.MOTA"], "%.1f" % m["mot.Car.HOTA"], cost,
                                                        train_seconds("%s/%s.train.log" % (out, name),
                                                                      "InterRM trained:")]) + " |")


def inter_tables(out, names):
    head = ["| %s | Car 3D @0.7 | Ped 3D @0.5 | Cyc 3D @0.5 | L2 mAP | L2 mAPH | Car MOTA | Car HOTA | "
            "tracker + InterRM ms, 50 tracks (median / p95) | train s |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    tracked = metrics("sim_intra_track")
    base = "| " + " | ".join(["+ IntraRM + tracker, no InterRM"] + ap_cells(tracked) + [
        "%.1f" % tracked["mot.Car.MOTA"], "%.1f" % tracked["mot.Car.HOTA"], "", ""]) + " |"
    hist = sorted((int(re.match(r"inter_h(\d+)$", n).group(1)), n) for n in names if re.match(r"inter_h\d+$", n))
    lines = [head[0] % "history N (implicit encoding)", head[1], base]
    lines += [inter_row(out, n, "N = %d" % h) for h, n in hist]
    print("\n".join(lines))
    write_between("inter-sim-history", lines)
    pes = [n for n in names if n.startswith("inter_pe_")]
    if pes:
        lines = [head[0] % "positional encoding", head[1], base]
        shipped = [n for h, n in hist if h == shipped_history()]
        if shipped:
            lines.append(inter_row(out, shipped[0], "implicit (time offset as an input feature)"))
        label = {"temporal": "temporal (sinusoids of the time offset)", "spatial": "spatial (sinusoids of the position)"}
        lines += [inter_row(out, n, label.get(n[len("inter_pe_"):], n)) for n in pes]
        print("\n".join(lines))
        write_between("inter-sim-pe", lines)


def table3(inter_name):
    # + IntraRM: the shipped models/lwd3d/intra_rm.pt, config/relation/intra_lwd3d_m1.yaml (chosen by the ablation)
    rows = [("base (LWD-3D, anchor head)", "base"), ("+ IntraRM", "intra_lwd3d_m1"),
            ("+ IntraRM + tracker", "sim_intra_track"), ("+ IntraRM + tracker + InterRM", "sim_" + inter_name)]
    waymo = ["| stages | " + " | ".join("%s L1 mAP/mAPH | %s L2 mAP/mAPH" % (c, c) for c in CLASSES) +
             " | mean L2 mAP | **mean L2 mAPH** |", "| --- " * (2 + 2 * len(CLASSES) + 1) + "|"]
    kitti = ["| stages | Car 3D @0.7 | Pedestrian 3D @0.5 | Cyclist 3D @0.5 | Car BEV @0.7 | mean L2 mAPH |",
             "| --- | --- | --- | --- | --- | --- |"]
    mot = ["| stages | class | MOTA | MOTP | IDSW | IDSW per 100 GT tracks | HOTA | DetA | AssA | id stability % | "
           "MOTA / IDSW / HOTA within 48 m |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for label, name in rows:
        m = metrics(name)
        cells = []
        for c in CLASSES:
            for lv in ("L1", "L2"):
                cells.append("%.2f / %.2f" % (m["waymo.%s.%s.AP" % (c, lv)], m["waymo.%s.%s.APH" % (c, lv)]))
        waymo.append("| " + " | ".join([label] + cells + ["%.2f" % m["waymo.mean.L2.AP"],
                                                          "**%.2f**" % m["waymo.mean.L2.APH"]]) + " |")
        kitti.append("| " + " | ".join([label] + ["%.2f" % m["kitti.%s.3d.R40.moderate" % c] for c in CLASSES] + [
            "%.2f" % m["kitti.Car.bev.R40.moderate"], "%.2f" % m["waymo.mean.L2.APH"]]) + " |")
        if "mot.Car.MOTA" in m:
            near_file = "out/heldout/%s/eval_48m/metrics.json" % name
            near = json.load(open(near_file)) if os.path.exists(near_file) else None
            for c in CLASSES:
                p = "mot.%s." % c
                tracks = max(1.0, m["mot_detail.%s.GT_tracks" % c])
                within = "%.2f / %d / %.2f" % (near[p + "MOTA"], near[p + "IDSW"], near[p + "HOTA"]) if near else "-"
                mot.append("| %s | %s | %.2f | %.2f | %d | %.1f | %.2f | %.2f | %.2f | %.1f | %s |" % (
                    label, c, m[p + "MOTA"], m[p + "MOTP"], m[p + "IDSW"], 100.0 * m[p + "IDSW"] / tracks,
                    m[p + "HOTA"], m[p + "DetA"], m[p + "AssA"], m.get(p + "IdStability", float("nan")), within))
    lines = waymo + [""] + kitti + [""] + mot
    print("\n".join(lines))
    write_between("table3-sim", lines)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "table3":
        table3(sys.argv[2])
    elif len(sys.argv) >= 3 and sys.argv[1] in ("intra", "inter"):
        (intra_table if sys.argv[1] == "intra" else inter_tables)(sys.argv[2], sys.argv[3:])
    else:
        sys.exit(__doc__)
