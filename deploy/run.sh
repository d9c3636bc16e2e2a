#!/usr/bin/env bash
# The README's first command: install dependencies, build (incremental when run again), show one
# detection, then run the service on models/default in the foreground.
#   bash deploy/run.sh              the demo scene: a plain synthetic road with one obstacle of
#                                   20-50 cm at 10-25 m, through models/synth-demo
#   bash deploy/run.sh IMAGE...     your own frames (PNG, JPEG, WebP) through models/default
#   TOD_GRPC_PORT (default 8001), TOD_HTTP_PORT (default 8000), BUILD_DIR (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/deps.sh build
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" -j "$(nproc)" --target tod tod_server tod_client tod_load
BIN="$BUILD_DIR/bin"
MODEL=models/default

if [[ $# -gt 0 ]]; then
  frames=("$@")
  demo_model=$MODEL
else
  # The demo scene (tod synth is deterministic for a seed). The synthetic camera is not the real
  # camera models/default was trained on, so the demo uses the bundle trained on synthetic scenes.
  if [[ ! -d out/demo/data ]]; then
    "$BIN/tod" synth --out out/demo/data --train 0 --test 1 --seed 5 --obstacles 1 \
      --size-m 0.2 0.5 --distance-m 10 25
  fi
  frames=("$(find out/demo/data/leftImg8bit/test -name '*.png' | sort | head -n 1)")
  demo_model=models/synth-demo
fi
"$BIN/tod" detect --model "$demo_model" --out out/demo "${frames[@]}"
for frame in "${frames[@]}"; do
  stem=$(basename "${frame%.*}")
  echo "overlay: out/demo/${stem}_overlay.png  (obstacles: out/demo/${stem}.json)"
done

echo "starting tod_server on $MODEL (gRPC :${TOD_GRPC_PORT:-8001}, HTTP :${TOD_HTTP_PORT:-8000}); Ctrl-C drains and stops"
exec "$BIN/tod_server" --model "$MODEL" --grpc-port "${TOD_GRPC_PORT:-8001}" \
  --http-port "${TOD_HTTP_PORT:-8000}"
