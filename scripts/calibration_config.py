#!/usr/bin/python3
"""A detector YAML's score calibration taken out, or put back from scripts/fit_score_calibration.py's output.

  calibration_config.py strip CONFIG OUT            CONFIG without inference.point_refine.score_calibration
  calibration_config.py insert CONFIG OUT LOG...    CONFIG (stripped) with the weights each fit's LOG ends with
                                                     ("score_calibration: {Class: [...]}"), after `centroid:`

Used by scripts/train_default.sh and scripts/experiments/long_range.sh to refit the calibration of new weights: their
boxes without calibration, one fit per class, the weights written into a copy of the config.
"""
import re
import sys


def strip(text):
    out, skip = [], False
    for line in text.split("\n"):
        if line.strip().startswith("score_calibration:"):
            skip = True
            continue
        if skip and line.startswith("      "):
            continue
        skip = False
        out.append(line)
    return "\n".join(out)


def insert(text, logs):
    weights = {}
    for log in logs:
        m = re.search(r"score_calibration: \{(\w+): (\[[^]]*\])\}", open(log).read())
        if not m:
            sys.exit("calibration_config.py: %s holds no score_calibration line" % log)
        weights[m.group(1)] = m.group(2)
    out = []
    for line in text.split("\n"):
        out.append(line)
        if line.strip().startswith("centroid:"):
            out.append("    score_calibration:   # refitted with scripts/fit_score_calibration.py")
            out += ["      %s: %s" % (c, w) for c, w in sorted(weights.items())]
    return "\n".join(out)


def main(argv):
    if len(argv) < 4 or argv[1] not in ("strip", "insert") or (argv[1] == "insert" and len(argv) < 5):
        sys.exit(__doc__)
    text = strip(open(argv[2]).read())
    if argv[1] == "insert":
        text = insert(text, argv[4:])
    open(argv[3], "w").write(text)


if __name__ == "__main__":
    main(sys.argv)
