#!/usr/bin/env bash
# Reproduces models/default: synthetic training and test frames from `tod synth`, then
# `tod train` (which also evaluates the new bundle on the test split and stores the numbers in
# its manifest). Deterministic for the seeds below. Takes a few minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-build/bin}
DATA=${DATA:-out/synth-default}
"$BIN/tod" synth --out "$DATA" --train 80 --test 30 --seed 1
"$BIN/tod" train --data "$DATA" --out models/default --seed 1 --max-frames 80
