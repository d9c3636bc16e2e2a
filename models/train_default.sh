#!/usr/bin/env bash
# Reproduces models/default: `tod train` on the 50 real Lost and Found frames of the team's
# development set (fs-laf-dev: Lost and Found frames, Pinggera et al., IROS 2016, with the
# Fishyscapes Lost & Found labels, Blum et al.; both for non-commercial research only, which the
# manifest records). Real frames give by far the better real-frame model: the same recipe trained
# on our synthetic scenes, or on synthetic scenes and real frames together, does worse on real
# frames it has not seen (docs/results.md#how-the-default-got-here). About 3 minutes on 2 cores.
#
# Then the held-out estimate in models/default-eval.json: the same recipe trained on frames 0-34
# and evaluated on frames 35-49 (a folder of links with a split.txt, since the shelf is read-only).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
DEV=${DEV:-../shared/data/fs-laf-dev}
TERMS="fs-laf-dev: 50 Lost and Found frames (Pinggera et al., IROS 2016) with Fishyscapes Lost & Found labels (Blum et al.); Lost and Found and Fishyscapes are for non-commercial research"
"$BIN/tod" train --data "$DEV" --out models/default --seed 1 --no-eval --data-terms "$TERMS"

SPLIT=out/fs-laf-dev-0-34
mkdir -p "$SPLIT"
ln -sfn "$(realpath "$DEV/images")" "$SPLIT/images"
ln -sfn "$(realpath "$DEV/labels_masks")" "$SPLIT/labels_masks"
{ for i in $(seq 0 34); do echo "train $i"; done; for i in $(seq 35 49); do echo "test $i"; done; } \
  > "$SPLIT/split.txt"
"$BIN/tod" train --data "$SPLIT" --out out/default-0-34 --seed 1 --no-eval --data-terms "$TERMS"
"$BIN/tod" eval --data "$SPLIT" --split test --model out/default-0-34 \
  --json models/default-eval.json --plots models/default-plots
