#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# FCC spheres wholly inside a sphere container of radius 20 r and 40 r: the
# packing fraction and time of vdbpack's placement search, against the best of
# N random offsets and rotations of the same lattice (bench/ref_fcc_sphere.py,
# numpy, independent of vdbpack), measured in the same run.
# Targets (issue 2): >= 0.637 at 20 r, >= 0.687 at 40 r, in well under a second.
# Usage: bash bench/bench_lattice_sphere.sh [TRIALS=2000]   (after a build)
set -euo pipefail
cd "$(dirname "$0")/.."
VDBPACK=${VDBPACK:-build/vdbpack}
TRIALS=${1:-2000}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
printf '%-6s %-22s %8s %9s %8s\n' ratio method count fraction seconds
for R in 20 40; do
  for rot in "" "--rotate"; do
    "$VDBPACK" pack "sphere:$R" --radius 1 $rot -o "$tmp/s.vdb" --json > "$tmp/j.json"
    python3 - "$tmp/j.json" "$R" "${rot:-search}" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print("%-6s %-22s %8d %9.5f %8.3f" % (sys.argv[2] + "r", "vdbpack " + sys.argv[3], d["count"],
      d["packing_fraction"], d["pack_seconds"]))
PY
  done
  /usr/bin/python3 bench/ref_fcc_sphere.py "$R" 1 "$TRIALS" > "$tmp/r.json"
  python3 - "$tmp/r.json" "$R" "$TRIALS" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print("%-6s %-22s %8d %9.5f %8.3f   (mean of trials %.5f)" % (sys.argv[2] + "r",
      "best of %s random" % sys.argv[3], d["count"], d["fraction"], d["seconds"], d["mean_fraction"]))
PY
done
