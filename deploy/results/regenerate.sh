#!/usr/bin/env bash
# Re-runs every study committed under deploy/results/ with the command docs/05 gives
# for it, and puts its table and plots in place. The studies are lockstep runs
# (deterministic): a run on another machine gives the same sweep.csv byte for byte.
# Usage: bash deploy/results/regenerate.sh [TACTILE]   (default: target/release/tactile)
set -euo pipefail
cd "$(dirname "$0")/../.."
tactile=${1:-target/release/tactile}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
wall=deploy/scenarios/wall-delay.toml
# The sweep into a scratch folder; its table, and each plot the study's folder holds
# (the sweep's own, by name; `positions-50ms-none.svg` and the like from that run).
study() { # name, then the sweep's arguments
  local name=$1
  shift
  "$tactile" sweep "$@" --out "$tmp/$name" -q >/dev/null
  cp "$tmp/$name"/sweep.csv deploy/results/"$name"/
  for svg in deploy/results/"$name"/*.svg; do
    local file
    file=$(basename "$svg")
    if [ -f "$tmp/$name/$file" ]; then
      cp "$tmp/$name/$file" "$svg"
    else
      cp "$(run_plot "$tmp/$name" "$file")" "$svg"
    fi
  done
  echo "deploy/results/$name: $(($(wc -l <"$tmp/$name/sweep.csv") - 1)) runs"
}
# `PLOT-50ms-KIND.svg`: PLOT.svg of the run at a 50 ms round trip with control KIND.
run_plot() {
  python3 - "$1" "$2" <<'PY'
import csv, re, sys
folder, file = sys.argv[1], sys.argv[2]
plot, ms, kind = re.fullmatch(r"(\w+)-(\d+)ms-(\w+)\.svg", file).groups()
for row in csv.DictReader(open(f"{folder}/sweep.csv")):
    delay = row["network.forward.delay"]
    if delay == f"[{ms},{ms},{ms}]" and row["control.kind"] == kind:
        print(f"{folder}/{row['run']}/{plot}.svg")
        break
else:
    sys.exit(f"no run at {ms} ms with {kind} for {file}")
PY
}
study wall-delay "$wall" \
  --set 'network.forward.delay=[0,0,0],[10,10,10],[50,50,50],[100,100,100],[200,200,200]' \
  --set control.kind=none,tdpa,wave,mmt --set 'network.backward.delay=[0,0,0]'
study press-speed "$wall" --set operator.move_s=1,2,4,8,12,16 \
  --set control.kind=tdpa,wave,mmt --set network.forward.delay_ms=100 \
  --set network.backward.delay_ms=100 --set samples=24000
study mmt-map "$wall" \
  --set 'environment.objects[0].stiffness=[100,100,100],[300,300,300],[600,600,600],[1000,1000,1000],[2000,2000,2000],[3000,3000,3000]' \
  --set network.forward.delay_ms=0,10,50,100,200 --set control.kind=none,tdpa,wave,mmt \
  --set 'network.backward.delay=[0,0,0]'
study wall-change deploy/scenarios/wall-change.toml --set control.kind=none,tdpa,wave,mmt
# The task scenes (docs/16): round trips of 0 to 200 ms split evenly both ways, 2 ms
# of jitter each way, three seeds.
trips='[0,0,0],[25,25,25],[50,50,50],[75,75,75],[100,100,100]'
for scene in push-box peg-in-hole; do
  study "$scene-study" deploy/scenarios/$scene.toml \
    --set "network.forward.delay=$trips" --set "+network.backward.delay=$trips" \
    --set control.kind=none,tdpa,wave,mmt --set 'network.forward.jitter={jitter_ms=2.0}' \
    --set 'network.backward.jitter={jitter_ms=2.0}' --seeds 3
done
