#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# vdbpack's lattice fill against OpenVDB's own route to N points inside a mesh
# (vdb_tool: mesh -> level set -> fog -> scatter -> points; its points overlap
# freely), on the same mesh and voxel size, for N ~ 1M and 10M, in one run.
# Prints wall time, peak memory (max RSS), the time ratio, and vdbpack's peak
# memory per particle beyond the level set (peak RSS of the run minus that of
# the same run with a single particle, so the process and level set cancel).
# Targets (issue 2): vdbpack time <= vdb_tool's; <= 64 bytes per particle.
# Usage: bash bench/bench_vs_vdb_tool.sh [MESH] [N...]   (after a build)
set -euo pipefail
cd "$(dirname "$0")/.."
VDBPACK=${VDBPACK:-build/vdbpack}
MESH=${1:-vdb_samples/peanut.obj}
shift || true
COUNTS=("$@"); [ ${#COUNTS[@]} -gt 0 ] || COUNTS=(1000000 10000000)
command -v vdb_tool >/dev/null || { echo "vdb_tool not found (apt-get install libopenvdb-tools)"; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

run() { # label, command...; prints "seconds maxrss_kb"
  local label=$1; shift
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" > "$tmp/out.txt" 2> "$tmp/err.txt" || {
    echo "$label failed:"; cat "$tmp/err.txt"; exit 1; }
  cat "$tmp/time"
}
MEMBENCH=${MEMBENCH:-build/bench/bench_lattice_memory}

printf '%-9s %-9s %9s %9s %7s %10s %10s %9s %11s\n' N voxel vdbpack_s vdb_tool_s ratio \
  vdbpack_MB vdb_tool_MB placed B/particle
for N in "${COUNTS[@]}"; do
  # The whole CLI run (voxelize, pack, write) against vdb_tool's whole run at
  # the voxel size vdbpack chose.
  read -r t1 m1 < <(run vdbpack "$VDBPACK" pack "$MESH" --count "$N" -o "$tmp/a.vdb" --json)
  voxel=$(python3 -c "import json; print(json.load(open('$tmp/out.txt'))['voxel_size'])")
  placed=$(python3 -c "import json; print(json.load(open('$tmp/out.txt'))['count'])")
  read -r t2 m2 < <(run vdb_tool vdb_tool -read "$MESH" -mesh2ls voxel="$voxel" -ls2fog \
      -scatter count="$N" -points2vdb -write "$tmp/c.vdb")
  bpp=$("$MEMBENCH" "$MESH" "$N" "$voxel" | python3 -c "import json,sys; print(json.load(sys.stdin)['bytes_per_particle'])")
  python3 -c "
t1, t2, m1, m2 = $t1, $t2, $m1, $m2
print('%-9s %-9.4g %9.2f %9.2f %7.2f %10.0f %10.0f %9s %11s' % ('$N', $voxel, t1, t2, t1 / t2,
      m1 / 1024, m2 / 1024, '$placed', '$bpp'))"
done
echo "ratio = vdbpack time / vdb_tool time (target <= 1); B/particle = vdbpack's peak beyond"
echo "the resident level set, from build/bench/bench_lattice_memory (target <= 64)."
