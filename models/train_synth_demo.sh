#!/usr/bin/env bash
# Reproduces models/synth-demo, the bundle of the README's demo: `tod train` on 40 synthetic
# scenes (`tod synth --seed 1`). It is made for the demo's plain synthetic scene (one obstacle of
# 20-50 cm at 10-25 m on an open road), which the real-trained models/default, trained on one
# real camera's frames, does not handle: a synthetic frame is another camera to it. It is not a
# model for real frames (docs/results.md#plain-synthetic-scenes). About 3 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$BIN/tod" synth --out "$work/data" --train 40 --test 0 --seed 1
"$BIN/tod" train --data "$work/data" --out models/synth-demo --seed 1 --no-eval \
  --data-terms "40 synthetic scenes of tod synth --seed 1 (made by this project)"
