#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# vdbpack's `--method jam` against packing-generation's force-biased algorithm
# (FBA; V. Baranau, https://github.com/VasiliBaranov/packing-generation, MIT;
# Bezrukov et al. 2002), N equal spheres, timed in the same run (issue 28).
#
# Not comparable as is: FBA packs in a PERIODIC box (no walls; its only
# boundary mode), vdbpack packs inside the walled box:1,1,1, and walls cost
# density near them. The comparable vdbpack figure is its core fraction
# (--json "core_fraction": the spheres farther than 5 diameters from the wall)
# beside the whole box's "packing_fraction". FBA is serial; vdbpack uses all
# cores (default --threads): compare user CPU time as well as wall time.
#
# FBA settings (packing-generation's README and Docs/Examples/generation.conf):
#   contraction rate FBA_RATE (default 1.328910e-5, the example's), diameters
#   1, "Generation start: 1" (Poisson start), seed 1, periodic box of side L
#   with N*pi/6 / L^3 = phi_exp, the README's expected density for that rate:
#   phi_exp = 0.6 + 0.1 * (ln rate - ln 1e-3) / (ln 1e-7 - ln 1e-3) (0.6469
#   at the default rate, the example's). Its final fraction is
#   1 - "Final Porosity" in packing.nfo. Its time includes its own naive
#   O(N^2) closest-pair check after the run (it writes no packing.nfo if
#   spheres overlap). FBA alone, no -ls / -lsgd after it.
# vdbpack: `vdbpack pack box:1,1,1 --method jam --count N -o X.vdb --json`,
#   its output then checked by `vdbpack check` (not timed).
# Both timed by /usr/bin/time: wall, user CPU, max RSS.
#
# Usage: bash bench/bench_vs_fba.sh [PACKING_GENERATION_EXE] [N...]
#   N defaults to 100000. The executable may also come from
#   $PACKING_GENERATION. Without it, only vdbpack runs. To build it
#   (scratch folder, not part of this repository or its build):
#     git clone https://github.com/VasiliBaranov/packing-generation /tmp/pg
#     make -C /tmp/pg/_Release        # about 1.5 min; no dependencies
#     PACKING_GENERATION=/tmp/pg/_Release/PackingGeneration.exe \
#       bash bench/bench_vs_fba.sh 100000
#   FBA takes about 105 s CPU at 10 000 spheres on the 2-core dev machine and
#   grows faster than N: expect tens of minutes at 100 000.
# No pass/fail: figures and ratios are printed for the notes.
set -euo pipefail
cd "$(dirname "$0")/.."
VDBPACK=${VDBPACK:-build/vdbpack}
PG=${PACKING_GENERATION:-}
if [ $# -gt 0 ] && ! [[ "$1" =~ ^[0-9]+$ ]]; then PG=$1; shift; fi
COUNTS=("$@"); [ ${#COUNTS[@]} -gt 0 ] || COUNTS=(100000)
RATE=${FBA_RATE:-1.328910e-5}
for N in "${COUNTS[@]}"; do
  [[ "$N" =~ ^[0-9]+$ ]] && [ "$N" -ge 2 ] || { echo "bench_vs_fba: N must be an integer >= 2, not '$N'" >&2; exit 2; }
done
[ -x "$VDBPACK" ] || { echo "bench_vs_fba: $VDBPACK not built (bash scripts/setup.sh)" >&2; exit 1; }
VDBPACK=$(realpath "$VDBPACK")
if [ -n "$PG" ]; then
  [ -x "$PG" ] || { echo "bench_vs_fba: packing-generation '$PG' is not an executable" >&2; exit 1; }
  PG=$(realpath "$PG")
else
  echo "bench_vs_fba: packing-generation not given (set PACKING_GENERATION or pass its"
  echo "  executable first); see this script's header for how to build it. vdbpack only."
fi
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

timed() { # out_prefix, command...; writes PREFIX.time ("wall user maxrss_kb")
  local p=$1; shift
  /usr/bin/time -f "%e %U %M" -o "$p.time" "$@" > "$p.out" 2> "$p.err" || {
    echo "bench_vs_fba: failed: $*" >&2; tail -5 "$p.err" "$p.out" >&2; exit 1; }
}

echo "vdbpack: $VDBPACK ($(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))"
[ -z "$PG" ] || echo "FBA: $PG, contraction rate $RATE, seed 1, periodic box"
rows=()
for N in "${COUNTS[@]}"; do
  fba="- - - - -"
  if [ -n "$PG" ]; then
    d="$tmp/fba$N"; mkdir -p "$d"
    python3 - "$N" "$RATE" > "$d/generation.conf" <<'EOF'
import math, sys
n, rate = int(sys.argv[1]), float(sys.argv[2])
phi = 0.6 + 0.1 * (math.log(rate) - math.log(1e-3)) / (math.log(1e-7) - math.log(1e-3))
L = (n * math.pi / 6 / phi) ** (1 / 3)
print(f"Particles count: {n}\nPacking size: {L!r} {L!r} {L!r}\nGeneration start: 1\n"
      f"Seed: 1\nSteps to write: 1000000000\nBoundaries mode: 1\nContraction rate: {rate:e}")
EOF
    echo "N=$N: FBA running (started $(date -u +%H:%M:%S) UTC)..."
    (cd "$d" && timed "$tmp/fba$N" "$PG" -fba)
    [ -f "$d/packing.nfo" ] || { echo "bench_vs_fba: FBA wrote no packing.nfo (failed check?)" >&2; tail -5 "$tmp/fba$N.out" >&2; exit 1; }
    read -r fw fu fm < "$tmp/fba$N.time"
    read -r ffrac fit < <(python3 - "$d/packing.nfo" <<'EOF'
import sys
t = open(sys.argv[1]).read().splitlines()
por = float([l for l in t if l.strip().startswith("Final Porosity")][0].split(":")[1].split()[0])
it = int([l for l in t if l.strip().startswith("Total Iterations")][0].split(":")[1])
print(f"{1 - por:.4f} {it}")
EOF
)
    fba="$ffrac $fw $fu $fm $fit"
    echo "N=$N: FBA fraction $ffrac in $fw s wall, $fu s user, $fit iterations"
  fi
  echo "N=$N: vdbpack jam running (started $(date -u +%H:%M:%S) UTC)..."
  timed "$tmp/vp$N" "$VDBPACK" pack box:1,1,1 --method jam --count "$N" -o "$tmp/vp$N.vdb" --json
  read -r vw vu vm < "$tmp/vp$N.time"
  read -r vfrac vcore vz vratt < <(python3 - "$tmp/vp$N.out" <<'EOF'
import json, sys
j = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
print(f"{j['packing_fraction']:.4f} {j['core_fraction']:.4f} {j['mean_contacts']:.2f} {j['rattler_fraction']:.3f}")
EOF
)
  ck=ok; "$VDBPACK" check "$tmp/vp$N.vdb" --container box:1,1,1 > "$tmp/ck$N.out" 2>&1 || ck="FAILED($?)"
  rm -f "$tmp/vp$N.vdb"
  echo "N=$N: vdbpack fraction $vfrac (core $vcore, Z $vz) in $vw s wall, $vu s user; check $ck"
  rows+=("$N $vfrac $vcore $vz $vratt $vw $vu $vm $ck $fba")
done

echo
printf '%-8s | %-8s %-7s %-5s %-6s %8s %8s %7s %-5s | %-7s %8s %8s %7s %6s\n' \
  N vp_frac vp_core vp_Z rattl vp_wall vp_user vp_MB check fba_frac fba_wall fba_user fba_MB fba_it
for r in "${rows[@]}"; do
  read -r N vfrac vcore vz vratt vw vu vm ck ffrac fw fu fm fit <<< "$r"
  mb() { [ "$1" = - ] && echo - || echo $(( $1 / 1024 )); }
  printf '%-8s | %-8s %-7s %-5s %-6s %8s %8s %7s %-5s | %-7s %8s %8s %7s %6s\n' \
    "$N" "$vfrac" "$vcore" "$vz" "$vratt" "$vw" "$vu" "$(mb "$vm")" "$ck" "$ffrac" "$fw" "$fu" "$(mb "$fm")" "$fit"
done
if [ -n "$PG" ]; then
  echo
  echo "ratios, vdbpack / FBA (time: < 1 is vdbpack faster; fraction: vdbpack core and whole box against FBA's periodic box):"
  for r in "${rows[@]}"; do
    read -r N vfrac vcore vz vratt vw vu vm ck ffrac fw fu fm fit <<< "$r"
    python3 -c "
n, vw, vu, fw, fu = $N, $vw, $vu, $fw, $fu
vc, vf, ff, vm, fm = $vcore, $vfrac, $ffrac, $vm, $fm
print(f'N={n}: wall {vw/fw:.3f}, user CPU {vu/fu:.3f}, max RSS {vm/fm:.2f}; '
      f'core fraction {vc/ff:.4f} ({vc-ff:+.4f}), whole-box fraction {vf/ff:.4f} ({vf-ff:+.4f})')"
  done
fi
