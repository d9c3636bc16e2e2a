#!/usr/bin/env bash
# The one list of Debian 12 packages this project needs.
#   deploy/deps.sh build     install what building and testing need
#   deploy/deps.sh runtime   install only the shared libraries the binaries load
#   deploy/deps.sh --print [build|runtime]   print the list, install nothing
# Idempotent: packages already present are skipped. Works as root or through sudo.
set -euo pipefail

BUILD_PACKAGES=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libopencv-dev libopencv-contrib-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libeigen3-dev libspdlog-dev libfmt-dev nlohmann-json3-dev libcli11-dev
  prometheus-cpp-dev libmatio-dev zlib1g-dev libdeflate-dev
  libboost-dev libjpeg62-turbo-dev libpng-dev libwebp-dev libssl-dev
  libcpp-httplib-dev
  libgtest-dev libgmock-dev
  clang libclang-rt-14-dev
  openssl stress-ng curl
  python3-grpcio python3-protobuf
)
# libboost-dev: Boost.Beast/Asio (header-only) for tod_server's REST transport.
# libjpeg62-turbo-dev, libpng-dev, libwebp-dev: tod_server's strict image decoders.
# libssl-dev: TLS of tod_server's REST transport (Boost.Asio's ssl::stream) and token digests.
# libdeflate-dev: whole-buffer inflate of the plain-PNG decoder (core/data/plain_png.cc), twice
# zlib's speed on a frame's image data.
# zlib1g-dev: the MAT file bounds check inflates compressed variables (core/modd2/mat5_bounds.cc).
# libcpp-httplib-dev: only the HTTP client of tod_load and of the tests (not the server).
# clang, libclang-rt-14-dev: the libFuzzer targets (tests/fuzz/; libFuzzer and the sanitizer
# runtimes of Debian 12's clang 14). The production build stays on gcc.
# openssl: the service tests make a throw-away CA and certificates with the openssl command.
# curl: deploy/soak.sh (and its ctest soak_smoke) and deploy/bench_server.sh probe and scrape
# the server with it.
# python3-grpcio, python3-protobuf: a gRPC client this project did not write, for the ctest of
# the Open Inference Protocol's gRPC service (stubs made with Debian's protoc and grpc_python_plugin).
# stress-ng: loads the CPUs beside the service tests to check they hold on a busy machine.

RUNTIME_PACKAGES=(
  ca-certificates tini
  libopencv-core406 libopencv-imgproc406 libopencv-imgcodecs406 libopencv-ml406
  libopencv-contrib406
  libgrpc++1.51 libgrpc29 libprotobuf32
  libspdlog1.10 libfmt9 libprometheus-cpp-core1.0 libmatio11
  libjpeg62-turbo libpng16-16 libwebp7 libdeflate0 libssl3
  libcpp-httplib0.11
)
# libcpp-httplib0.11: tod_load's HTTP client; tod_server does not load it.
# libssl3: OpenSSL for tod_server's HTTPS (gRPC carries its own TLS in libgrpc29).

usage() {
  echo "usage: $0 build|runtime|--print [build|runtime]" >&2
  exit 2
}

[[ $# -ge 1 ]] || usage
case "$1" in
  build) wanted=("${BUILD_PACKAGES[@]}") ;;
  runtime) wanted=("${RUNTIME_PACKAGES[@]}") ;;
  --print)
    case "${2:-build}" in
      build) printf '%s\n' "${BUILD_PACKAGES[@]}" ;;
      runtime) printf '%s\n' "${RUNTIME_PACKAGES[@]}" ;;
      *) usage ;;
    esac
    exit 0
    ;;
  *) usage ;;
esac

missing=()
for pkg in "${wanted[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$pkg")
  fi
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "deps.sh: all ${#wanted[@]} $1 packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "deps.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
echo "deps.sh: installing ${#missing[@]} packages: ${missing[*]}"
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
