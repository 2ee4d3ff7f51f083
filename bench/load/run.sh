#!/usr/bin/env bash
# Load test against a local svrc-server on loopback (not in CI):
#   bash bench/load/run.sh [BUILD_DIR] [-- extra svrc_load_bench flags]
# Builds svrc-server and svrc_load_bench, starts the server (port 0, 2
# workers, temp data dir), runs 8 clients × 200 small jobs + 3 cancels,
# prints the numbers and stops the server.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build/bench}
shift || true
[[ "${1:-}" == "--" ]] && shift
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSVRC_BUILD_BENCH=ON >/dev/null
cmake --build "$BUILD" -j 2 --target svrc-server svrc_load_bench
tmp=$(mktemp -d)
"$BUILD/server/svrc-server" --listen=127.0.0.1:0 --workers=2 --queue-capacity=256 \
  --data-dir="$tmp/data" >"$tmp/stdout" 2>"$tmp/server.log" &
pid=$!
trap 'kill -TERM $pid 2>/dev/null || true; wait $pid 2>/dev/null || true; rm -rf "$tmp"' EXIT
for _ in $(seq 1 300); do grep -q '^listening on ' "$tmp/stdout" && break; sleep 0.1; done
addr=$(sed -n 's/^listening on //p' "$tmp/stdout")
echo "load: server $addr (2 workers)"
"$BUILD/bench/load/svrc_load_bench" --server "$addr" --clients 8 --jobs 200 --points 200 --cancels 3 "$@"
