#!/usr/bin/env bash
# The README's first command: install dependencies, build (incremental when run again), show one
# detection with the shipped default model, then run the service on it in the foreground.
#   TOD_GRPC_PORT (default 8001), TOD_HTTP_PORT (default 8000), BUILD_DIR (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/deps.sh build
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" -j "$(nproc)" --target tod tod_server tod_client tod_load
BIN="$BUILD_DIR/bin"
MODEL=models/default

# A first result a person can look at: one synthetic frame through the whole pipeline.
if [[ ! -d out/demo/data ]]; then
  "$BIN/tod" synth --out out/demo/data --train 0 --test 1 --seed 2026
fi
frame=$(find out/demo/data/leftImg8bit/test -name '*.png' | sort | head -n 1)
"$BIN/tod" detect --model "$MODEL" --out out/demo "$frame"
echo "overlay: out/demo/$(basename "${frame%.png}")_overlay.png"

echo "starting tod_server on $MODEL (gRPC :${TOD_GRPC_PORT:-8001}, HTTP :${TOD_HTTP_PORT:-8000}); Ctrl-C drains and stops"
exec "$BIN/tod_server" --model "$MODEL" --grpc-port "${TOD_GRPC_PORT:-8001}" \
  --http-port "${TOD_HTTP_PORT:-8000}"
