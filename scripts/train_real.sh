#!/usr/bin/env bash
# Trains the LWD-3D base detector on real KITTI object data (the full labelled set of 7,481 frames, which the user
# holds; licence CC BY-NC-SA 3.0, non-commercial) plus the simulated sets, on the standard train / val split of
# Chen et al. (MV3D: 3,712 / 3,769 frames), and evaluates it on the val half. Run with --help for the options.
#   1. links the split's frames into object-layout folders OUT/data/kitti_real/{train,val}/training/{velodyne,
#      label_2,calib} (symlinks to the user's files, never copies) and reports missing files;
#   2. simulates the simulated training sets when missing (as scripts/train_default.sh) and builds a ground-truth
#      database from them and the real train split (`ret3d train gtdb`);
#   3. trains (`ret3d train detector --resume`) from models/lwd3d_sim/detector.pt when present, else
#      models/lwd3d/detector.pt, with config/detector/lwd3d_anchor_robust.yaml: real train split (labels cover camera
#      2's view only, so no loss outside it) and simulated sets (labels all around);
#   4. evaluates on the val split: `ret3d detect --stages base`, `ret3d eval --metric kitti --kitti-recall devkit`
#      on every box and on the boxes in the camera's view (as scripts/experiments/real_scans.sh), prints the moderate
#      AP;
#   5. installs the model into --install DIR when asked.
# Resumable and idempotent: run it again after a stop and it continues from the last checkpoint; finished steps are
# skipped (markers OUT/*.done). Nothing is downloaded.
set -euo pipefail
CALLER_DIR=$(pwd)
cd "$(dirname "$0")/.."
REPO=$(pwd)
START=$(date +%s)
ME=train_real.sh

usage() {
  cat <<EOF
Usage: scripts/$ME KITTI_OBJECT_ROOT [options]

Trains the base detector on the real KITTI object training set (KITTI_OBJECT_ROOT/training/{velodyne,label_2,calib}
with FFFFFF.bin / FFFFFF.txt; KITTI_OBJECT_ROOT may also be the training folder itself) plus simulated scans, on the
train / val split of Chen et al. (MV3D, 3,712 / 3,769 frames), and evaluates it on the val frames.

Options (defaults in brackets):
  --split-dir DIR     folder holding train.txt and val.txt (one 6-digit frame id per line) [KITTI_OBJECT_ROOT/ImageSets]
                      They are not downloaded: take them from OpenPCDet (data/kitti/ImageSets/{train,val}.txt,
                      https://github.com/open-mmlab/OpenPCDet) or from the MV3D / 3DOP split
                      (https://xiaozhichen.github.io/files/mv3d/imagesets.tar.gz).
  --out DIR           work folder: linked data, database, model, logs, evaluation [out/train_real]
  --config FILE       detector config [config/detector/lwd3d_anchor_robust.yaml]
  --epochs N          train N epochs instead of the config's train.epochs (writes OUT/config.yaml, a copy of the
                      config with train.epochs changed) [the config's]
  --init FILE         start from these weights [models/lwd3d_sim/detector.pt if present, else models/lwd3d/detector.pt]
  --real-weight W     each real train frame is drawn W times per epoch on average [1]
  --sim-weight W      each simulated frame is drawn W times per epoch on average [0.5]
  --sim DIR           a simulated training folder (KITTI tracking layout, labels all around); repeatable; replaces
                      the default sets [data/sim_train_urban (urban 32 x 80 frames, seed 1000) and
                      data/sim_train_highway (highway 8 x 60 frames, seed 2000), simulated when missing]
  --no-sim            train on the real train split only
  --threads N         torch threads for training and detection [2]
  --install DIR       copy the trained model to DIR/detector.pt (only when given) []
  -h, --help          this help

Environment: RET3D (the binary) [build/devel/bin/ret3d], RET3D_SHARED_DATA (the project's data; its kitti_object
frames are the validation set of the project and are refused) [../shared/data].

Work and logs go to OUT: data/kitti_real/{train,val} (symlinks), gtdb/train.gtdb, detector.pt (checkpoints beside
it; --resume), train.log, val/{pred,eval,pred_camera_view,eval_camera_view}. Finished steps are skipped when run
again (delete OUT/<step>.done to redo one). Weights trained on KITTI data inherit its licence, CC BY-NC-SA 3.0
(non-commercial use only).
EOF
}

die() {
  echo "$ME: $*" >&2
  exit 1
}

# --- options
KITTI_ROOT=""
SPLIT_DIR=""
OUT=out/train_real
CONFIG=config/detector/lwd3d_anchor_robust.yaml
EPOCHS=""
INIT=""
REAL_WEIGHT=1
SIM_WEIGHT=0.5
SIM_DIRS=()
SIM_GIVEN=0
NO_SIM=0
THREADS=2
INSTALL=""
need() { [ $# -ge 2 ] && [ -n "$2" ] || die "$1 needs a value (--help)"; }
# Paths given on the command line are the caller's (the script works from the repository root).
abs() { case "$1" in /*) echo "$1" ;; *) echo "$CALLER_DIR/$1" ;; esac; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --split-dir) need "$@"; SPLIT_DIR=$(abs "$2"); shift 2 ;;
    --out) need "$@"; OUT=$(abs "$2"); shift 2 ;;
    --config) need "$@"; CONFIG=$(abs "$2"); shift 2 ;;
    --epochs) need "$@"; EPOCHS=$2; shift 2 ;;
    --init) need "$@"; INIT=$(abs "$2"); shift 2 ;;
    --real-weight) need "$@"; REAL_WEIGHT=$2; shift 2 ;;
    --sim-weight) need "$@"; SIM_WEIGHT=$2; shift 2 ;;
    --sim) need "$@"; SIM_DIRS+=("$(abs "$2")"); SIM_GIVEN=1; shift 2 ;;
    --no-sim) NO_SIM=1; shift ;;
    --threads) need "$@"; THREADS=$2; shift 2 ;;
    --install) need "$@"; INSTALL=$(abs "$2"); shift 2 ;;
    -*) die "unknown option $1 (--help)" ;;
    *)
      [ -z "$KITTI_ROOT" ] || die "one KITTI_OBJECT_ROOT only (got '$KITTI_ROOT' and '$1')"
      KITTI_ROOT=$(abs "$1")
      shift
      ;;
  esac
done
[ -n "$KITTI_ROOT" ] || { usage >&2; die "KITTI_OBJECT_ROOT is missing"; }
number='^[0-9]+([.][0-9]+)?$'
[[ $REAL_WEIGHT =~ $number ]] || die "--real-weight '$REAL_WEIGHT': a number >= 0"
[[ $SIM_WEIGHT =~ $number ]] || die "--sim-weight '$SIM_WEIGHT': a number >= 0"
[[ $THREADS =~ ^[1-9][0-9]*$ ]] || die "--threads '$THREADS': a whole number >= 1"
[ -z "$EPOCHS" ] || [[ $EPOCHS =~ ^[1-9][0-9]*$ ]] || die "--epochs '$EPOCHS': a whole number >= 1"
[ -f "$CONFIG" ] || die "--config $CONFIG: no such file"
((NO_SIM && SIM_GIVEN)) && die "--sim and --no-sim together"

RET3D=${RET3D:-$REPO/build/devel/bin/ret3d}
if [ ! -x "$RET3D" ]; then scripts/setup.sh; fi
[ -x "$RET3D" ] || die "no ret3d binary at $RET3D (build ret3d_cli, or set RET3D)"
ret3d() { "$RET3D" "$@"; }
# With the cores busy, spinning OpenMP threads make libtorch many times slower (see launch/ret3d.launch).
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}

# --- the KITTI root and the split
[ -d "$KITTI_ROOT" ] || die "KITTI_OBJECT_ROOT $KITTI_ROOT: no such folder"
if [ -d "$KITTI_ROOT/training/velodyne" ]; then
  KITTI_TRAINING=$(realpath "$KITTI_ROOT/training")
elif [ -d "$KITTI_ROOT/velodyne" ]; then
  KITTI_TRAINING=$(realpath "$KITTI_ROOT")
else
  die "$KITTI_ROOT: not a KITTI object root (expected $KITTI_ROOT/training/{velodyne,label_2,calib}: the KITTI 3D" \
      "object detection set, data_object_velodyne.zip, data_object_label_2.zip, data_object_calib.zip from" \
      "https://www.cvlibs.net/datasets/kitti/eval_object.php?obj_benchmark=3d)"
fi
for d in velodyne label_2 calib; do
  [ -d "$KITTI_TRAINING/$d" ] || die "$KITTI_TRAINING/$d: missing (the object set's training/$d folder)"
done
# The project's own six labelled KITTI frames are its validation set: never trained on (the symlinked folders below
# would otherwise hide them from the guard of `ret3d train gtdb`, which refuses paths under kitti_object).
SHARED_KITTI=${RET3D_SHARED_DATA:-$REPO/../shared/data}/kitti_object/training
if [ -d "$SHARED_KITTI" ] && [ "$(realpath "$SHARED_KITTI")" = "$KITTI_TRAINING" ]; then
  die "$KITTI_ROOT is the project's validation set ($SHARED_KITTI): never train on it; give your own full KITTI" \
      "object set"
fi

SPLIT_DIR=${SPLIT_DIR:-$KITTI_ROOT/ImageSets}
for s in train val; do
  if [ ! -f "$SPLIT_DIR/$s.txt" ]; then
    die "no split file $SPLIT_DIR/$s.txt. The train / val split of Chen et al. (MV3D, 3,712 / 3,769 frame ids, one" \
        "per line) is not downloaded by this script: take train.txt and val.txt from OpenPCDet's data/kitti/ImageSets" \
        "(https://github.com/open-mmlab/OpenPCDet/tree/master/data/kitti/ImageSets) or from" \
        "https://xiaozhichen.github.io/files/mv3d/imagesets.tar.gz, put them in one folder and pass --split-dir DIR"
  fi
done
# Frame ids, trimmed of blanks and carriage returns (files written on Windows).
ids() { tr -d '\r' <"$1" | awk 'NF { print $1 }'; }
for s in train val; do
  bad=$(ids "$SPLIT_DIR/$s.txt" | grep -cvE '^[0-9]{6}$' || true)
  [ "$bad" = 0 ] || die "$SPLIT_DIR/$s.txt: $bad lines are not 6-digit frame ids, e.g." \
                        "'$(ids "$SPLIT_DIR/$s.txt" | grep -vE '^[0-9]{6}$' | head -1)'"
done
n_train=$(ids "$SPLIT_DIR/train.txt" | sort -u | wc -l)
n_val=$(ids "$SPLIT_DIR/val.txt" | sort -u | wc -l)
n_both=$(comm -12 <(ids "$SPLIT_DIR/train.txt" | sort -u) <(ids "$SPLIT_DIR/val.txt" | sort -u) | wc -l)
((n_train > 0 && n_val > 0)) || die "$SPLIT_DIR: train.txt ($n_train ids) and val.txt ($n_val ids) must not be empty"
((n_both == 0)) || die "$SPLIT_DIR: $n_both frame ids are in both train.txt and val.txt"
if ((n_train != 3712 || n_val != 3769)); then
  echo "$ME: warning: the split has $n_train train / $n_val val frames, not the standard 3,712 / 3,769" >&2
fi

# Those six frames are frames of the full set too: in its train half, a model learnt them, and
# scripts/experiments/real_scans.sh (which evaluates on them) no longer measures it on unseen scans.
if [ -d "$SHARED_KITTI/velodyne" ]; then
  seen=$(comm -12 <(ids "$SPLIT_DIR/train.txt" | sort -u) \
    <(find "$SHARED_KITTI/velodyne" -maxdepth 1 -name '*.bin' -printf '%f\n' | sed 's/\.bin$//' | sort -u) |
    paste -sd ' ')
  [ -z "$seen" ] || echo "$ME: note: frames $seen of the project's validation set ($SHARED_KITTI) are in train.txt:" \
                         "scripts/experiments/real_scans.sh figures of this model are not on unseen scans" >&2
fi

mkdir -p "$OUT"
OUT=$(realpath "$OUT")
case "/$OUT/" in
  */kitti_object/*) die "--out $OUT: a folder under one named kitti_object (\`ret3d train gtdb\` refuses those" \
                        "paths, to protect the project's validation set); choose another" ;;
esac
LOG_PREFIX="$ME:"
step() { echo "$LOG_PREFIX $*"; }

# --- 1. train and val folders of symlinks (object layout)
REAL=$OUT/data/kitti_real
STAMP=$(
  echo "$KITTI_TRAINING"
  ids "$SPLIT_DIR/train.txt" | sort -u | md5sum
  ids "$SPLIT_DIR/val.txt" | sort -u | md5sum
)
if [ ! -f "$REAL/.done" ] || [ "$(cat "$REAL/.done")" != "$STAMP" ]; then
  if [ -f "$REAL/.done" ] && compgen -G "$OUT/detector.pt*" >/dev/null; then
    die "$OUT was trained on another KITTI root or split ($REAL/.done); use another --out, or delete $OUT"
  fi
  step "1. linking the split's frames from $KITTI_TRAINING into $REAL/{train,val}"
  rm -rf "$REAL"
  missing=0
  for s in train val; do
    for d in velodyne label_2 calib; do
      ext=txt
      [ $d = velodyne ] && ext=bin
      mkdir -p "$REAL/$s/training/$d"
      lost=$(ids "$SPLIT_DIR/$s.txt" | sort -u | while read -r id; do
        [ -f "$KITTI_TRAINING/$d/$id.$ext" ] || echo "$id"
      done)
      if [ -n "$lost" ]; then
        n=$(echo "$lost" | wc -l)
        missing=$((missing + n))
        echo "$ME: $s: $n files missing in $KITTI_TRAINING/$d, e.g. $(echo "$lost" | head -5 | sed "s/\$/.$ext/" |
          tr '\n' ' ')" >&2
      fi
      ids "$SPLIT_DIR/$s.txt" | sort -u | sed "s|.*|$KITTI_TRAINING/$d/&.$ext|" |
        xargs -r ln -sf -t "$REAL/$s/training/$d" 2>/dev/null || true
    done
  done
  ((missing == 0)) || die "$missing files of the split are missing (above): is $KITTI_ROOT the full KITTI object" \
                          "training set (velodyne, label_2, calib) and does the split belong to it?"
  echo "$STAMP" >"$REAL/.done"
fi
for s in train val; do
  for d in velodyne label_2 calib; do
    n=$(find "$REAL/$s/training/$d" -maxdepth 1 -name '??????.*' | wc -l)
    want=$n_train
    [ $s = val ] && want=$n_val
    ((n == want)) || die "$REAL/$s/training/$d holds $n frames, the split $want: delete $REAL and run again"
  done
done
step "1. real data: $n_train train / $n_val val frames linked in $REAL"

# --- 2. simulated sets and the ground-truth database
if ((NO_SIM)); then
  SIM_DIRS=()
elif ((!SIM_GIVEN)); then
  source scripts/simulate_once.sh
  mkdir -p data
  step "2. simulating the simulated training sets when missing (data/sim_train_{urban,highway}; logs in $OUT)"
  simulate_once data/sim_train_urban config/sim/urban_street.yaml 32 80 1000 "$OUT/sim_train_urban.log"
  simulate_once data/sim_train_highway config/sim/highway.yaml 8 60 2000 "$OUT/sim_train_highway.log"
  SIM_DIRS=(data/sim_train_urban data/sim_train_highway)
fi
for d in "${SIM_DIRS[@]}"; do [ -d "$d" ] || die "--sim $d: no such folder"; done

GTDB=$OUT/gtdb/train.gtdb
GTDB_SETTINGS="data ${SIM_DIRS[*]} $REAL/train; config $CONFIG"
if [ ! -f "$OUT/gtdb.done" ] || [ "$(cat "$OUT/gtdb.done")" != "$GTDB_SETTINGS" ]; then
  step "2. ground-truth database from ${SIM_DIRS[*]:-no simulated set} and the real train split -> $GTDB"
  ret3d train gtdb --data "${SIM_DIRS[@]}" "$REAL/train" --config "$CONFIG" --out "$GTDB" >"$OUT/gtdb.log" 2>&1 ||
    { tail -20 "$OUT/gtdb.log" >&2; die "ret3d train gtdb failed (log: $OUT/gtdb.log)"; }
  echo "$GTDB_SETTINGS" >"$OUT/gtdb.done"
fi
step "2. $(tail -1 "$OUT/gtdb.log")"

# --- 3. training
TRAIN_CONFIG=$CONFIG
if [ -n "$EPOCHS" ]; then
  # No --epochs in the CLI: a copy of the config with train.epochs replaced (added when the config has none).
  TRAIN_CONFIG=$OUT/config.yaml
  awk -v n="$EPOCHS" '
    /^[^ #]/ {
      if (in_train && !done) { print "  epochs: " n; done = 1 }
      in_train = /^train:/
    }
    in_train && /^  epochs:/ { print "  epochs: " n; done = 1; next }
    { print }
    END { if (in_train && !done) print "  epochs: " n; else if (!done) print "train:\n  epochs: " n }
  ' "$CONFIG" >"$TRAIN_CONFIG.new"
  TRAIN_CONFIG=$TRAIN_CONFIG.new  # moved into place once the settings check below has passed
fi
if [ -z "$INIT" ]; then
  INIT=models/lwd3d/detector.pt
  [ -f models/lwd3d_sim/detector.pt ] && INIT=models/lwd3d_sim/detector.pt
fi
[ -f "$INIT" ] || die "--init $INIT: no such model"
MODEL=$OUT/detector.pt
DATA=("$REAL/train" "${SIM_DIRS[@]}")
WEIGHTS=("$REAL_WEIGHT")
COVERS=(camera)
for _ in "${SIM_DIRS[@]}"; do
  WEIGHTS+=("$SIM_WEIGHT")
  COVERS+=(all)
done
# What the model is trained from: a later run with other settings must not resume or reuse it silently.
config_md5=$(md5sum <"$TRAIN_CONFIG" | cut -c1-12)
SETTINGS="data ${DATA[*]}; weights ${WEIGHTS[*]}; labels cover ${COVERS[*]}; init $INIT; config $CONFIG"
SETTINGS+="${EPOCHS:+ with $EPOCHS epochs} (md5 $config_md5)"
if [ -f "$OUT/train.settings" ] && [ "$(cat "$OUT/train.settings")" != "$SETTINGS" ]; then
  rm -f "$OUT/config.yaml.new"
  die "$MODEL was trained (or begun) with other settings. Then: $(cat "$OUT/train.settings"). Now: $SETTINGS." \
      "Use another --out, or delete $OUT/train.settings, $OUT/train.done and $MODEL* to train again"
fi
if [ -n "$EPOCHS" ]; then
  mv "$TRAIN_CONFIG" "$OUT/config.yaml"
  TRAIN_CONFIG=$OUT/config.yaml
fi
if [ ! -f "$OUT/train.done" ]; then
  rm -f "$OUT/val.done"
  echo "$SETTINGS" >"$OUT/train.settings"
  step "3. training from $INIT with $TRAIN_CONFIG on ${DATA[*]} (weights ${WEIGHTS[*]}; labels cover ${COVERS[*]})" \
       "-> $MODEL; log: $OUT/train.log (resumes from the last checkpoint when run again)"
  t0=$(date +%s)
  ret3d train detector --data "${DATA[@]}" --data-weights "${WEIGHTS[@]}" --labels-cover "${COVERS[@]}" \
    --config "$TRAIN_CONFIG" --init "$INIT" --gt-database "$GTDB" --out "$MODEL" --threads "$THREADS" --resume \
    >>"$OUT/train.log" 2>&1 || { tail -20 "$OUT/train.log" >&2; die "training failed (log: $OUT/train.log)"; }
  touch "$OUT/train.done"
  step "3. training took $((($(date +%s) - t0) / 60)) min (this run)"
fi
step "3. $(grep '^trained' "$OUT/train.log" | tail -1)"

# --- 4. evaluation on the val split
VAL=$OUT/val
if [ ! -f "$OUT/val.done" ]; then
  step "4. detecting on the $n_val val frames -> $VAL/pred"
  rm -rf "$VAL"
  mkdir -p "$VAL"
  ret3d detect --data "$REAL/val" --detector-model "$MODEL" --stages base --out "$VAL/pred" --threads "$THREADS" \
    >"$VAL/detect.log" 2>&1 || { tail -20 "$VAL/detect.log" >&2; die "ret3d detect failed (log: $VAL/detect.log)"; }
  # The labels cover camera 2's image only and the detector sees all around: keep the boxes whose 2D box (fields
  # 5-8, clipped to the image by `ret3d detect`) overlaps the image, as scripts/experiments/real_scans.sh.
  mkdir -p "$VAL/pred_camera_view"
  for f in "$VAL"/pred/*.txt; do
    [ -f "$f" ] || continue  # no result files at all: the evaluations below count every object missed
    awk '$7 > $5 && $8 > $6' "$f" >"$VAL/pred_camera_view/$(basename "$f")"
  done
  # Devkit recall sampling: right with >= 40 objects per class and difficulty (the 3,769 val frames have thousands).
  for p in pred pred_camera_view; do
    e=eval${p#pred}
    ret3d eval --gt "$REAL/val" --pred "$VAL/$p" --out "$VAL/$e" --metric kitti --kitti-recall devkit \
      --threads "$THREADS" >"$VAL/$e.txt" 2>&1 || { tail -20 "$VAL/$e.txt" >&2; die "ret3d eval failed ($VAL/$e.txt)"; }
  done
  touch "$OUT/val.done"
fi
python3 - "$VAL" <<'EOF'
import json, sys
val = sys.argv[1]
print("KITTI AP on the val split, moderate, R40 (R11 in brackets), devkit recall sampling:")
print("%-26s %-11s %17s %17s" % ("boxes", "class", "3D", "BEV"))
for e, what in (("eval_camera_view", "in the camera's view"), ("eval", "all (360 degrees)")):
    m = json.load(open("%s/%s/metrics.json" % (val, e)))
    for c in ("Car", "Pedestrian", "Cyclist"):
        cell = lambda k: "%6.2f (%6.2f)" % (m.get("kitti.%s.%s.R40.moderate" % (c, k), float("nan")),
                                            m.get("kitti.%s.%s.R11.moderate" % (c, k), float("nan")))
        print("%-26s %-11s %17s %17s" % (what, c, cell("3d"), cell("bev")))
print("reports: %s/eval_camera_view/report.md, %s/eval/report.md" % (val, val))
EOF

# --- 5. install
if [ -n "$INSTALL" ]; then
  mkdir -p "$INSTALL"
  cp "$MODEL" "$INSTALL/detector.pt"
  step "5. installed $MODEL -> $INSTALL/detector.pt (trained on KITTI: CC BY-NC-SA 3.0, non-commercial use only)"
fi
step "done in $((($(date +%s) - START) / 60)) min $((($(date +%s) - START) % 60)) s (this run); work in $OUT"
