#!/usr/bin/env bash
# Reproduces models/default: `tod train` on the 100 real Lost and Found frames of the team's
# development set (fs-laf-dev: Lost and Found frames, Pinggera et al., IROS 2016, with the
# Fishyscapes Lost & Found labels, Blum et al.; both for non-commercial research only, which the
# manifest records). Real frames give by far the better real-frame model: the same recipe trained
# on our synthetic scenes, or on synthetic scenes and real frames together, does worse on real
# frames it has not seen (docs/results.md#how-the-default-got-here). About 7 minutes on 2 cores.
#
# Then the estimate in models/default-eval.json: the same recipe cross-validated over the 100
# frames, 5 folds of 20 consecutive frames, each trained on the other 80, two forest seeds
# (`tod cv`; about 70 minutes on 2 cores). --keep-models keeps the 10 fold bundles under
# out/cv-default so that detection options can be measured on them with `tod eval` alone.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
DEV=${DEV:-../shared/data/fs-laf-dev}
TERMS="fs-laf-dev: 100 Lost and Found frames (Pinggera et al., IROS 2016) with Fishyscapes Lost & Found labels (Blum et al.); Lost and Found and Fishyscapes are for non-commercial research"
mkdir -p out
{ for i in $(seq 0 99); do echo "train $i"; done; } > out/fs-laf-dev-0-99.txt
"$BIN/tod" train --data "$DEV" --split-file out/fs-laf-dev-0-99.txt --out models/default --seed 1 \
  --no-eval --data-terms "$TERMS"

"$BIN/tod" cv --data "$DEV" --work out/cv-default --folds 5 --seeds 2 --seed 1 \
  --keep-models --json models/default-eval.json
