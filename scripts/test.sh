#!/usr/bin/env bash
# Builds and runs every test. Assumes scripts/setup.sh ran (README's test
# command does both). Stages, each timed:
#   1. Release build of everything, all test suites (ctest)
#   2. ASan+UBSan build (-O1) of the core-labelled suites, run
#   3. TSan build of the server's job library + its unit suites (queue,
#      pool, store, journal, job manager, WatchJob flow control), run with
#      halt_on_error=1: a data race fails CI. server/ synchronises with
#      std::mutex/std::condition_variable, which TSan intercepts; suppressions
#      (tests/server/tsan.supp, empty today) may only name the uninstrumented
#      Debian gRPC/Abseil/protobuf libraries (docs/service.md "TSan").
# Tests named LONG_* (minutes each, e.g. CreaseMesh.LONG_HingeMeshes) are left
# out; run them with `ctest --test-dir build/release -R LONG_`.
# Env: SVRC_JOBS (default: nproc), SVRC_SKIP_SANITIZE=1 to skip stage 2,
# SVRC_SKIP_TSAN=1 to skip stage 3.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
JOBS=${SVRC_JOBS:-$(nproc)}
export CCACHE_DIR=${CCACHE_DIR:-$ROOT/build/.ccache}
export CTEST_OUTPUT_ON_FAILURE=1

stage_start=0
stage() { stage_start=$(date +%s); echo "=== [$(date -u +%H:%M:%S)] stage: $*"; }
stage_end() { echo "=== stage done in $(( $(date +%s) - stage_start )) s: $*"; }
t0=$(date +%s)

stage "configure+build release"
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DSVRC_WERROR=ON >/dev/null
cmake --build build/release -j "$JOBS"
stage_end "build release"

stage "tests (release)"
ctest --test-dir build/release -j "$JOBS" --timeout 600 -E LONG_
stage_end "tests release"

if [[ "${SVRC_SKIP_SANITIZE:-0}" != 1 ]]; then
  stage "configure+build asan/ubsan (core)"
  # -O1 -g1 (as TSan below) and only the core-labelled suites
  # (svrc_core_tests): what `ctest -L core` runs (the full -O2 build took
  # 686 s of the 1477 s CI run of 2d53b0b).
  cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
    -DSVRC_SANITIZE=address,undefined -DSVRC_BUILD_SERVICE=OFF -DSVRC_WERROR=ON >/dev/null
  cmake --build build/asan -j "$JOBS" --target svrc_core_tests
  stage_end "build asan"

  stage "tests (asan/ubsan, label core)"
  ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build/asan -L core -j "$JOBS" --timeout 900 -E LONG_
  stage_end "tests asan"
fi
if [[ "${SVRC_SKIP_TSAN:-0}" != 1 ]]; then
  stage "configure+build tsan (server job library + unit suites)"
  # -O1 -g1: half the compile time of -O2 -g; line tables are all TSan
  # reports need. Only svrc_server_unit_tests (svrc_server_jobs + core), not
  # the gRPC service: see tests/server/tsan.supp for why.
  cmake -S . -B build/tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
    -DSVRC_SANITIZE=thread >/dev/null
  cmake --build build/tsan -j "$JOBS" --target svrc_server_unit_tests
  stage_end "build tsan"

  stage "tests (tsan, server unit suites)"
  # halt_on_error=1: the first report ends the run with exit code 66.
  TSAN_OPTIONS="suppressions=$ROOT/tests/server/tsan.supp halt_on_error=1 second_deadlock_stack=1" \
    timeout 900 build/tsan/tests/server/svrc_server_unit_tests
  stage_end "tests tsan"
fi
echo "=== all stages done in $(( $(date +%s) - t0 )) s"
