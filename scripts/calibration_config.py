#!/usr/bin/python3
"""A detector YAML's score calibration taken out, or put back from scripts/fit_score_calibration.py's output.

  calibration_config.py strip CONFIG OUT            CONFIG without inference.point_refine.score_calibration
  calibration_config.py insert CONFIG OUT LOG...    CONFIG (stripped) with the weights each fit's LOG ends with
                                                     ("score_calibration: {Class: [...]}"), after `centroid:`

Used by scripts/train_default.sh and scripts/experiments/long_range.sh to refit the calibration of new weights: their
boxes without calibration, one fit per class, the weights written into a copy of the config.

A CONFIG that starts from another (`base: FILE`, as the C++ reader resolves it: maps merged key by key, anything else
replaced whole) is written resolved, without `base:` (and without comments), so OUT stands on its own wherever it is
and `ret3d train set-config` stores the whole config; a CONFIG without `base:` keeps its text and comments.
"""
import os
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


def merged(base, over):
    if not isinstance(base, dict) or not isinstance(over, dict):
        return over
    out = dict(base)
    for key, value in over.items():
        out[key] = merged(out[key], value) if key in out else value
    return out


def resolved(path, chain=()):
    import yaml
    doc = yaml.safe_load(open(path))
    if not isinstance(doc, dict) or "base" not in doc:
        return doc
    base = os.path.join(os.path.dirname(path), doc.pop("base"))
    if os.path.realpath(base) in chain:
        sys.exit("calibration_config.py: %s: the bases form a cycle" % path)
    return merged(resolved(base, chain + (os.path.realpath(path),)), doc)


def resolved_text(path):
    """The text of CONFIG: as it is without `base:`, else its chain resolved into one document."""
    text = open(path).read()
    if not re.search(r"^base:", text, re.M):
        return text
    import yaml
    doc = resolved(path)
    refine = doc.setdefault("inference", {}).setdefault("point_refine", {})
    refine.setdefault("centroid", {})  # insert() places the weights after `centroid:`
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)


def main(argv):
    if len(argv) < 4 or argv[1] not in ("strip", "insert") or (argv[1] == "insert" and len(argv) < 5):
        sys.exit(__doc__)
    text = strip(resolved_text(argv[2]))
    if argv[1] == "insert":
        text = insert(text, argv[4:])
    open(argv[3], "w").write(text)


if __name__ == "__main__":
    main(sys.argv)
