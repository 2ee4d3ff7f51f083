#!/usr/bin/env bash
# Installs every Debian (bookworm) package svrc, its tests and its benchmarks
# need. Run as root. Idempotent: does nothing when all are installed.
# Used by README.md, .ci/run (through scripts/test.sh) and the Dockerfile.
#   scripts/setup.sh            build + test + bench packages
#   scripts/setup.sh --runtime  only what the server and CLI need at run time
set -euo pipefail

BUILD_PKGS=(
  build-essential cmake ninja-build ccache pkg-config git ca-certificates
  libabsl-dev libspdlog-dev libdraco-dev
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc grpc-proto
  libgtest-dev libgmock-dev
)
# Test oracles and peers: GMP (exact rational predicates), CGAL (Delaunay
# oracle, bench peer), tetgen (bench peer, mesh reader), gmsh and VTK
# (independent readers of our writers), python3-grpcio (thin-client test).
TEST_PKGS=(
  libgmp-dev libcgal-dev tetgen gmsh python3 python3-vtk9 python3-numpy python3-grpcio
  zlib1g-dev
  clang libclang-rt-14-dev  # libFuzzer targets (tests/fuzz, docs/fuzzing.md)
  openssl  # tests/server/security_test.cc makes its TLS certificates
)
RUNTIME_PKGS=(
  libabsl20220623 libspdlog1.10 libdraco7 libgrpc++1.51 libprotobuf32 libgmp10 ca-certificates
)

if [[ "${1:-}" == "--runtime" ]]; then
  PKGS=("${RUNTIME_PKGS[@]}")
else
  PKGS=("${BUILD_PKGS[@]}" "${TEST_PKGS[@]}")
fi

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi

if [[ $(id -u) -ne 0 ]]; then
  echo "setup: missing packages (${missing[*]}); run as root" >&2
  exit 1
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
