#!/usr/bin/env bash
# Soak test of svrc-server on loopback (not in CI), bounded in time:
#   bash bench/soak/run.sh [BUILD_DIR] [SECONDS=60] [CLIENTS=8]
# CLIENTS shell loops drive the `svrc` CLI against one server (2 workers,
# fixed loopback port, temp data dir) for SECONDS: each submits a job with a
# unique request id and input name (--watch; random sizes 300..30000 points),
# 1 in 8 cancels its job, 1 in 8 watches with a 0.3 s timeout (a disconnect
# mid-stream) and re-watches. Halfway the server is killed with SIGKILL and
# restarted on the same data dir; clients retry with the same request id
# (idempotent). At the end every accepted request must map to exactly one job
# in a terminal state. Prints: jobs accepted/completed/cancelled/failed, lost
# (must be 0), duplicated (must be 0), p50/p99 submit→terminal latency as seen
# by the clients (including retries over the restart), server RSS over time.
set -uo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build/harden}
SECS=${2:-60}
CLIENTS=${3:-8}
PORT=${SOAK_PORT:-50917}
ADDR=127.0.0.1:$PORT
SVRC=$BUILD/client/svrc
SERVER=$BUILD/server/svrc-server
cmake --build "$BUILD" -j 2 --target svrc-server svrc >/dev/null || exit 1
tmp=$(mktemp -d)
data=$tmp/data
mkdir -p "$tmp/in" "$tmp/res"
python3 - "$tmp/in" <<'PY'
import random, sys
for n in (300, 3000, 30000):
    r = random.Random(n)
    with open(f"{sys.argv[1]}/base{n}.node", "w") as f:
        f.write(f"{n} 3 0 0\n")
        for i in range(n):
            f.write(f"{i+1} {r.random():.6f} {r.random():.6f} {r.random():.6f}\n")
PY
start_server() {
  "$SERVER" --listen="$ADDR" --workers=2 --queue-capacity=256 --data-dir="$data" \
    >"$tmp/stdout" 2>>"$tmp/server.log" &
  spid=$!
  for _ in $(seq 1 100); do grep -q '^listening on ' "$tmp/stdout" 2>/dev/null && return 0; sleep 0.1; done
  echo "soak: server did not start"; return 1
}
cleanup() { kill -TERM "$spid" 2>/dev/null; wait "$spid" 2>/dev/null; kill -TERM "$rsspid" 2>/dev/null; rm -rf "$tmp"; }
trap cleanup EXIT
start_server || exit 1
echo "soak: server $ADDR pid $spid, ${CLIENTS} clients, ${SECS} s, kill -9 at $((SECS / 2)) s"
t_start=$(date +%s.%N)
# RSS sampler (follows the restart through the pid file).
echo "$spid" >"$tmp/pid"
( while :; do p=$(cat "$tmp/pid"); r=$(awk '/VmRSS/{print $2}' /proc/$p/status 2>/dev/null);
    echo "$(date +%s.%N) ${r:-0}" >>"$tmp/rss"; sleep 1; done ) &
rsspid=$!
deadline=$(( $(date +%s) + SECS ))
client() {
  local c=$1 k=0
  while (( $(date +%s) < deadline )); do
    k=$((k + 1))
    local rid="c${c}-${k}" sizes=(300 300 3000 3000 30000) n
    n=${sizes[$((RANDOM % 5))]}
    cp "$tmp/in/base$n.node" "$tmp/in/$rid.node"
    local t0 t1 rc mode=$((RANDOM % 8)) tries=0 id=""
    t0=$(date +%s.%N)
    while (( tries < 40 )); do
      tries=$((tries + 1))
      out=$("$SVRC" submit "$tmp/in/$rid.node" --server "$ADDR" --request-id "$rid" 2>/dev/null)
      rc=$?
      if (( rc == 0 )); then id=$(echo "$out" | tail -1); break; fi
      sleep 0.25  # server down (restart): retry with the same request id
    done
    [[ -z "$id" ]] && { echo "$rid NOTACCEPTED" >>"$tmp/res/$c"; continue; }
    if (( mode == 0 )); then "$SVRC" cancel "$id" --server "$ADDR" >/dev/null 2>&1; fi
    if (( mode == 1 )); then timeout 0.3 "$SVRC" watch "$id" --server "$ADDR" >/dev/null 2>&1; fi
    tries=0
    while (( tries < 40 )); do
      tries=$((tries + 1))
      "$SVRC" watch "$id" --server "$ADDR" >/dev/null 2>&1
      rc=$?
      (( rc == 0 || rc == 5 || rc == 6 )) && break
      sleep 0.25
    done
    t1=$(date +%s.%N)
    echo "$rid $id $rc $(echo "$t1 - $t0" | bc)" >>"$tmp/res/$c"
  done
}
for c in $(seq 1 "$CLIENTS"); do client "$c" & done
sleep $((SECS / 2))
echo "soak: kill -9 $spid at $(echo "$(date +%s.%N) - $t_start" | bc | cut -c1-5) s"
kill -9 "$spid"; wait "$spid" 2>/dev/null
rm -f "$tmp/stdout"
start_server || exit 1
echo "$spid" >"$tmp/pid"
echo "soak: restarted, pid $spid"
wait $(jobs -p | grep -v "^$rsspid\$" | grep -v "^$spid\$") 2>/dev/null
# Let the last accepted jobs finish (clients stopped at the deadline).
sleep 2
"$SVRC" list --server "$ADDR" --page-size 1000 >"$tmp/list" 2>&1
kill "$rsspid" 2>/dev/null
python3 - "$tmp" <<'PY'
import glob, sys, collections
tmp = sys.argv[1]
res = []
for f in glob.glob(f"{tmp}/res/*"):
    for line in open(f):
        res.append(line.split())
accepted = [r for r in res if r[1] != "NOTACCEPTED"]
jobs = [l.split() for l in open(f"{tmp}/list").read().splitlines()[1:] if l.strip()]
by_input = collections.defaultdict(list)
state = {}
for j in jobs:
    by_input[j[-1]].append(j[0]); state[j[0]] = j[1]
lost = dup = 0
for r in accepted:
    ids = by_input.get(r[0] + ".node", [])
    if len(ids) == 0 or state.get(r[1]) not in ("SUCCEEDED", "FAILED", "CANCELLED"): lost += 1
    if len(ids) > 1: dup += 1
codes = collections.Counter(r[2] for r in accepted)
lat = sorted(float(r[3]) for r in accepted)
def pct(p): return lat[min(len(lat) - 1, int(p * len(lat)))] if lat else 0
states = collections.Counter(state.values())
print(f"soak: requests {len(res)}, accepted {len(accepted)}, not accepted {len(res)-len(accepted)}")
print(f"soak: server jobs {len(jobs)} by state {dict(states)}; client exit codes {dict(codes)}")
print(f"soak: lost {lost} (must be 0), duplicated {dup} (must be 0)")
print(f"soak: latency submit->terminal p50 {pct(0.5):.2f} s, p99 {pct(0.99):.2f} s, max {lat[-1] if lat else 0:.2f} s")
rss = [l.split() for l in open(f"{tmp}/rss")]
t0 = float(rss[0][0])
print("soak: server RSS MiB every ~5 s: " + " ".join(f"{float(t)-t0:.0f}s:{int(r)/1024:.0f}" for t, r in rss[::5]))
print(f"soak: RSS max {max(int(r) for _, r in rss)/1024:.0f} MiB")
PY
grep -c "re-queued after a restart" "$tmp/server.log" | sed 's/^/soak: jobs re-queued by the restart: /'
