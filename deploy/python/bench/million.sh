#!/usr/bin/env bash
# A million-sample in-process run from the command and from Python, interleaved, as
# whole processes: docs/15-python.md's "within 1.1 times the command's time".
# Usage (from the repository's root, with the package installed in PYTHON's
# environment and a release build of the command):
#   bash deploy/python/bench/million.sh [PAIRS] [PYTHON] [TACTILE]
set -euo pipefail
pairs=${1:-7}
python=${2:-python3}
tactile=${3:-target/release/tactile}
scenario=deploy/scenarios/lockstep-1e6.toml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for k in $(seq "$pairs"); do
  rm -rf "$tmp/cli" "$tmp/py"
  c=$( { /usr/bin/time -f "%e" "$tactile" run "$scenario" --in-process -q --no-trace --out "$tmp/cli" >/dev/null; } 2>&1 | tail -1)
  p=$( { /usr/bin/time -f "%e" "$python" -c '
import sys, tactile
r = tactile.run(tactile.Scenario.load(sys.argv[1]), out=sys.argv[2], trace_format=None)
assert r.completed and r.summary["samples_sent"] == 1_000_000' "$scenario" "$tmp/py"; } 2>&1 | tail -1)
  echo "pair $k: command $c s, python $p s, ratio $(echo "$p / $c" | bc -l | cut -c1-5)"
done
