#!/usr/bin/env bash
# Server throughput and memory on real frames (issue 11): starts tod_server --workers 2 on a
# model, drives it with tod_load over gRPC at concurrency 1, 2 and 4 (closed loop), then sends
# at least --requests requests over a mix of real and synthetic frames and reports the server's
# peak and current RSS (VmHWM / VmRSS from /proc). Prints one Markdown table per part.
#
#   bash deploy/bench_server.sh --frames DIR [--model DIR] [--seconds S] [--requests N]
#                               [--workers W] [--threads-per-request T] [--build DIR]
# DIR holds the real frames (PNG/JPEG, e.g. ../shared/data/fs-laf-dev/images); synthetic frames
# of the same size are made with `tod synth` in a temporary directory.
set -euo pipefail
cd "$(dirname "$0")/.."

frames="" model=models/default seconds=30 requests=500 workers=2 threads=1 build=build
while [[ $# -gt 0 ]]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --model) model=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --requests) requests=$2; shift 2 ;;
    --workers) workers=$2; shift 2 ;;
    --threads-per-request) threads=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
done
[[ -d "$frames" ]] || { echo "--frames DIR is required (a folder of real frames)" >&2; exit 2; }
bin="$build/bin"

work=$(mktemp -d)
server_pid=""
cleanup() {
  if [[ -n "$server_pid" ]] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT

# The mixed set: every real frame, plus a fifth as many synthetic ones of 2048 x 1024.
mkdir -p "$work/real" "$work/mixed"
n_real=0
while IFS= read -r f; do
  ln -s "$(realpath "$f")" "$work/real/$(basename "$f")"
  ln -s "$(realpath "$f")" "$work/mixed/real_$(basename "$f")"
  n_real=$((n_real + 1))
done < <(find -L "$frames" -maxdepth 1 -type f \( -name '*.png' -o -name '*.jpg' \) | sort)
n_synth=$(( (n_real + 4) / 5 ))
[[ $n_real -gt 0 ]] || { echo "no PNG or JPEG frame in $frames" >&2; exit 2; }
"$bin/tod" synth --out "$work/synth" --train 0 --test "$n_synth" --seed 11 >/dev/null
find "$work/synth" -name '*.png' -path '*leftImg8bit*' | while IFS= read -r f; do
  ln -s "$f" "$work/mixed/synth_$(basename "$f")"
done

port_grpc=$((20000 + RANDOM % 20000))
port_http=$((port_grpc + 1))
"$bin/tod_server" --model "$model" --host 127.0.0.1 --grpc-port "$port_grpc" \
  --http-port "$port_http" --workers "$workers" --threads-per-request "$threads" \
  --queue 64 --log-level warn >"$work/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 1 600); do
  curl -sf "http://127.0.0.1:$port_http/v2/health/ready" >/dev/null && break
  sleep 0.1
done
curl -sf "http://127.0.0.1:$port_http/v2/health/ready" >/dev/null ||
  { echo "server did not become ready:" >&2; cat "$work/server.log" >&2; exit 1; }

rss_mb() { awk -v key="$1:" '$1 == key { printf "%.0f", $2 / 1024 }' "/proc/$server_pid/status"; }
ok_requests() {
  curl -s "http://127.0.0.1:$port_http/metrics" |
    awk '/^tod_requests_total/ && /code="OK"/ { s += $2 } END { printf "%d", s }'
}

echo "## tod_load on $n_real real frames ($workers workers, $threads thread(s) per request)"
echo
echo "| concurrency | requests/s | p50 ms | p99 ms | errors |"
echo "|---|---|---|---|---|"
for c in 1 2 4; do
  "$bin/tod_load" --addr "127.0.0.1:$port_grpc" --images "$work/real" --concurrency "$c" \
    --duration "$seconds" --warmup 2 --json "$work/load_$c.json" >/dev/null
  json_number() { grep -oE "\"$1\": *[0-9.eE+-]+" "$work/load_$c.json" | head -n 1 | grep -oE '[0-9.eE+-]+$'; }
  requests_sent=$(json_number requests) succeeded=$(json_number succeeded)
  printf '| %s | %.2f | %.0f | %.0f | %d |\n' "$c" "$(json_number throughput_rps)" \
    "$(json_number p50)" "$(json_number p99)" "$((requests_sent - succeeded))"
done

# Memory: keep sending the mixed set until the server has answered `requests` requests.
while [[ $(ok_requests) -lt $requests ]]; do
  "$bin/tod_load" --addr "127.0.0.1:$port_grpc" --images "$work/mixed" --concurrency 4 \
    --duration "$seconds" --warmup 0 >/dev/null
done
echo
echo "## tod_server memory after $(ok_requests) answered requests ($n_real real + $n_synth synthetic frames)"
echo
echo "| peak RSS (VmHWM) MB | RSS now MB |"
echo "|---|---|"
echo "| $(rss_mb VmHWM) | $(rss_mb VmRSS) |"
