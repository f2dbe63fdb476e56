#!/usr/bin/env python3
"""The summary scripts/demo.sh prints after a replay: what went in (the played bag), what came out (the recorded
/objects: frames, objects per frame and class, track ids), the stages' own figures from the recorded /diagnostics
(frames dropped, processing time and latency p50 / p95) and, when `ret3d eval` scored the run, its per-class AP and
tracking figures (read from its metrics.json; the evaluation itself is ret3d eval's, not repeated here).

Usage: demo_summary.py --input BAG --record BAG [--metrics metrics.json] [--report report.md] [--stages NOTE]
Exits 1 (saying why) when the recording holds no /objects message.
"""
import argparse
import json
import sys

import rosbag

CLASSES = {1: "Car", 2: "Pedestrian", 3: "Cyclist"}
# The nodelets in pipeline order, as launch/ret3d.launch names them.
STAGES = ["ret3d_detector", "ret3d_intra", "ret3d_tracker", "ret3d_inter", "ret3d_markers"]


def read_input(path):
    with rosbag.Bag(path) as bag:
        info = bag.get_type_and_topic_info().topics
        clouds = info["/points"].message_count if "/points" in info else 0
        truth = info["/ground_truth/objects"].message_count if "/ground_truth/objects" in info else 0
        duration = bag.get_end_time() - bag.get_start_time() if bag.get_message_count() else 0.0
    return clouds, truth, duration


def read_record(path):
    frames = 0
    per_class = {name: 0 for name in CLASSES.values()}
    other = 0
    tracks = {name: set() for name in CLASSES.values()}
    diagnostics = {}  # stage -> {key: value} of its last report
    with rosbag.Bag(path) as bag:
        for topic, msg, _ in bag.read_messages(topics=["/objects", "/diagnostics"]):
            if topic == "/objects":
                frames += 1
                for o in msg.objects:
                    name = CLASSES.get(o.label)
                    if name is None:
                        other += 1
                        continue
                    per_class[name] += 1
                    if o.track_id != 0:
                        tracks[name].add(o.track_id)
            else:
                for status in msg.status:
                    stage = status.name.split(":")[0].lstrip("/")
                    diagnostics[stage] = {kv.key: kv.value for kv in status.values}
    return frames, per_class, other, tracks, diagnostics


def number(values, key):
    try:
        return float(values[key])
    except (KeyError, ValueError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--input", required=True, help="the bag that was played")
    ap.add_argument("--record", required=True, help="the bag replay.launch recorded")
    ap.add_argument("--metrics", help="ret3d eval's metrics.json")
    ap.add_argument("--report", help="ret3d eval's report.md")
    ap.add_argument("--stages", default="", help="a note on the stages that ran")
    args = ap.parse_args()

    clouds, truth, duration = read_input(args.input)
    frames, per_class, other, tracks, diagnostics = read_record(args.record)
    print("ret3d demo summary")
    rate = (clouds - 1) / duration if clouds > 1 and duration > 0 else 0.0
    print(f"  input     {args.input}: {clouds} clouds, {duration:.1f} s ({rate:.1f} Hz)")
    if frames == 0:
        print(f"  output    {args.record}: no /objects message: the pipeline published nothing", file=sys.stderr)
        return 1
    missing = max(clouds - frames, 0)
    print(f"  output    {args.record}: /objects for {frames} of {clouds} clouds"
          + (f" ({missing} missing, {100.0 * missing / clouds:.1f} %)" if missing else " (none missing)"))
    if args.stages:
        print(f"  stages    {args.stages}")
    total = sum(per_class.values()) + other
    parts = ", ".join(f"{name} {count / frames:.1f}" for name, count in per_class.items())
    print(f"  objects   {total / frames:.1f} per frame ({parts})")
    ids = ", ".join(f"{name} {len(t)}" for name, t in tracks.items())
    print(f"  tracks    {sum(len(t) for t in tracks.values())} track ids ({ids})")

    if diagnostics:
        print("  stage               frames in  out  dropped  processing p50 / p95 ms  latency p50 / p95 ms")
        for stage in STAGES:
            d = diagnostics.get(stage)
            if d is None:
                continue
            f_in, f_out = number(d, "frames in"), number(d, "frames out")
            dropped = number(d, "frames dropped")
            p50, p95 = number(d, "processing p50 (ms)"), number(d, "processing p95 (ms)")
            l50, l95 = number(d, "latency since cloud stamp p50 (ms)"), number(d, "latency since cloud stamp p95 (ms)")
            print(f"  {stage:<18} {f_in:>10.0f} {f_out:>4.0f} {dropped:>8.0f}"
                  f"  {p50:>12.1f} / {p95:<9.1f}  {l50:>10.1f} / {l95:.1f}")
        print("  (the stages' last /diagnostics report; latency from the cloud's stamp, in the bag's time)")
        # Why frames were dropped or what was worked around (README "Diagnostics"), where anything was.
        for stage in STAGES:
            d = diagnostics.get(stage, {})
            counted = [f"{key} {number(d, key):.0f}" for key in d
                       if key.startswith(("dropped.", "degraded.")) and (number(d, key) or 0) > 0]
            if counted:
                print(f"  {stage:<18} {', '.join(counted)}")
    else:
        print("  (no /diagnostics recorded: no per-stage figures)")

    if args.metrics:
        with open(args.metrics) as f:
            m = json.load(f)
        # metrics.json is flat: "kitti.<Class>.<3d|bev>.R40.moderate", "mot.<Class>.<MOTA|IDSW|HOTA|IdStability>".
        def cell(key, fmt):
            v = m.get(key)
            return format(v, fmt) if v is not None else "-".rjust(len(format(0, fmt)))

        print(f"  scores    ret3d eval against the bag's /ground_truth/objects ({truth} frames):")
        print("            KITTI AP R40 moderate (front camera view); CLEAR MOT and HOTA (3D IoU >= 0.5); ids stable:")
        print("            % of covered ground-truth track-frames under their track's most frequent id (centres < 2 m)")
        print("            class        3D AP  BEV AP    MOTA  IDSW    HOTA  ids stable")
        for name in CLASSES.values():
            print(f"            {name:<11} {cell(f'kitti.{name}.3d.R40.moderate', '7.2f')}"
                  f" {cell(f'kitti.{name}.bev.R40.moderate', '7.2f')} {cell(f'mot.{name}.MOTA', '7.2f')}"
                  f" {cell(f'mot.{name}.IDSW', '5.0f')} {cell(f'mot.{name}.HOTA', '7.2f')}"
                  f" {cell(f'mot.{name}.IdStability', '11.1f')}")
        print(f"            all classes{'':>38}{cell('mot.all.IdStability', '11.1f')}")
    if args.report:
        print(f"  report    {args.report} (plots beside it)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
