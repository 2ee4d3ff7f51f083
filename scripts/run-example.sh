#!/usr/bin/env bash
# The main job on the bundled example, through the service. Assumes
# scripts/setup.sh ran. Builds svrc and svrc-server, starts the server on a
# free loopback port with a temporary data dir, submits
# docs/examples/two_rooms.poly (a PLC: two rooms, an internal wall, a max
# volume in one room) with --watch, writes the mesh to out/, prints a summary
# and stops the server.
# Env: SVRC_BUILD_DIR (default build/release), SVRC_EXAMPLE_OUT (default out),
#      SVRC_SKIP_BUILD=1 to use the binaries already built (the ctest does).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SVRC_BUILD_DIR:-build/release}
OUT=${SVRC_EXAMPLE_OUT:-out}
EXAMPLE=docs/examples/two_rooms.poly

if [[ "${SVRC_SKIP_BUILD:-0}" != 1 ]]; then
  cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD" -j "$(nproc)" --target svrc svrc-server
fi
SVRC="$BUILD/client/svrc"
SERVER="$BUILD/server/svrc-server"

tmp=$(mktemp -d)
"$SERVER" --listen=127.0.0.1:0 --workers=2 --data-dir="$tmp/data" >"$tmp/stdout" 2>"$tmp/server.log" &
server_pid=$!
cleanup() {
  kill -TERM "$server_pid" 2>/dev/null || true
  wait "$server_pid" 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT

for _ in $(seq 1 300); do
  grep -q '^listening on ' "$tmp/stdout" 2>/dev/null && break
  kill -0 "$server_pid" 2>/dev/null || break
  sleep 0.1
done
addr=$(sed -n 's/^listening on //p' "$tmp/stdout" | head -1)
if [[ -z "$addr" ]]; then
  echo "run-example: svrc-server did not start:" >&2
  cat "$tmp/server.log" >&2
  exit 1
fi
echo "run-example: svrc-server listening on $addr (data dir $tmp/data)"
"$SVRC" health --server "$addr"

mkdir -p "$OUT"
"$SVRC" submit "$EXAMPLE" --server "$addr" --watch -o "$OUT/two_rooms.vtu"
"$SVRC" list --server "$addr"

echo "run-example: mesh of $EXAMPLE written to $OUT/two_rooms.vtu:"
ls -l "$OUT"/two_rooms*
