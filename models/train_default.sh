#!/usr/bin/env bash
# Reproduces models/default: synthetic training and test frames from `tod synth`, `tod train` on
# 80 training frames, then `tod eval --record` on all 30 test frames, which prints the paper's
# tables and stores the numbers in the bundle's manifest. Deterministic for the seeds below; about
# 10 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
DATA=${DATA:-out/synth-default}
"$BIN/tod" synth --out "$DATA" --train 80 --test 30 --seed 1
"$BIN/tod" train --data "$DATA" --out models/default --seed 1 --max-frames 80 --no-eval
"$BIN/tod" eval --data "$DATA" --model models/default --record \
  --json models/default-eval.json --plots out/default-plots
