#!/usr/bin/env bash
# Reproduces models/default: `tod train` on the 50 real Lost and Found frames of the team's
# development set (fs-laf-dev: Lost and Found frames, Pinggera et al., IROS 2016, with the
# Fishyscapes Lost & Found labels, Blum et al.; both for non-commercial research only, which the
# manifest records). Real frames give by far the better real-frame model: the same recipe trained
# on our synthetic scenes, or on synthetic scenes and real frames together, does worse on real
# frames it has not seen (docs/results.md#how-the-default-got-here). About 3 minutes on 2 cores.
#
# Then the estimate in models/default-eval.json: the same recipe cross-validated over the 100
# frames, 5 folds of 20 consecutive frames, each trained on the other 80 (`tod cv`; about 35
# minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
DEV=${DEV:-../shared/data/fs-laf-dev}
TERMS="fs-laf-dev: 50 Lost and Found frames (Pinggera et al., IROS 2016) with Fishyscapes Lost & Found labels (Blum et al.); Lost and Found and Fishyscapes are for non-commercial research"
# models/default as shipped is trained on frames 0-49 (the set held 50 when it was trained).
mkdir -p out
{ for i in $(seq 0 49); do echo "train $i"; done; } > out/fs-laf-dev-0-49.txt
"$BIN/tod" train --data "$DEV" --split-file out/fs-laf-dev-0-49.txt --out models/default --seed 1 \
  --no-eval --data-terms "$TERMS"

"$BIN/tod" cv --data "$DEV" --work out/cv-default --folds 5 --seeds 1 --seed 1 \
  --json models/default-eval.json
