#!/usr/bin/env bash
# Makes the tiny synthetic dataset and model bundle the end-to-end tests share, through the real
# CLI. Small frames and few trees: this is a test fixture, not the default model.
set -euo pipefail
: "${TOD_BIN:?}" "${TOD_FIXTURE_DIR:?}"
rm -rf "$TOD_FIXTURE_DIR"
mkdir -p "$TOD_FIXTURE_DIR"
"$TOD_BIN" synth --out "$TOD_FIXTURE_DIR/data" --train 16 --test 6 --seed 7 --width 640 --height 320
# --paper out_of_fold_maps: out-of-fold maps (the default) would come from classifiers trained on 4 frames
# each, too few for maps worth learning from; the default path is covered by MasksCliTest.
"$TOD_BIN" train --data "$TOD_FIXTURE_DIR/data" --out "$TOD_FIXTURE_DIR/model" --seed 7 --trees 30 \
  --classifier-frames 8 --paper out_of_fold_maps > "$TOD_FIXTURE_DIR/train.log"
cat "$TOD_FIXTURE_DIR/train.log"
test -f "$TOD_FIXTURE_DIR/model/manifest.json"
