#!/usr/bin/env bash
# The main job on a bundled example. Assumes scripts/setup.sh ran.
# (Replaced by the service walk-through — start server, submit, watch, fetch —
# once the service lands; see docs/STATUS.md.)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" --target svrc
echo "run-example: nothing runnable yet (see docs/STATUS.md)" >&2
exit 1
