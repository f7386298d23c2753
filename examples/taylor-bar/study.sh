#!/usr/bin/env bash
# Resolution study of the Taylor bar (V2): one run per cell size, a table of final length L and
# foot diameter D (particle centres and surface) against the experiment and the seed's MPM
# results, with particle counts and wall times. Usage: ./study.sh BUILD_DIR CELL_MM...
set -euo pipefail
cd "$(dirname "$0")"
bin=$1; shift
mkdir -p study
table=study/table.md
{
  echo "| cell mm | particles | steps | L mm | D mm | D by direction mm | 2 r_max mm | L surf mm | D surf mm | L vs exp | D vs exp | seed MPM L, D mm | L vs seed | D vs seed | wall s | Mpart-steps/s |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
} > "$table"
for cell in "$@"; do
  out=study/taylor_${cell}.mpm
  start=$(date +%s.%N)
  "$bin/mpm-prep/mpm-prep" scene.toml --set grid.cell_size="$cell mm" 2> study/prep_${cell}.log |
    "$bin/mpm-run/mpm-run" --stats --progress lines -o "$out" 2> study/run_${cell}.log
  end=$(date +%s.%N)
  c=$("$bin/mpm-post/mpm-post" taylor "$out" --json)
  s=$("$bin/mpm-post/mpm-post" taylor "$out" --json --surface)
  steps=$(grep -o ', steps [0-9]*' study/run_${cell}.log | tail -1 | awk '{print $3}')
  rate=$(grep -o '[0-9.]* million particle-steps/s' study/run_${cell}.log | awk '{print $1}')
  python3 - "$cell" "$c" "$s" "$start" "$end" "$steps" "$rate" >> "$table" <<'PY'
import json, sys
cell, c, s, t0, t1, steps, rate = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), sys.argv[6], sys.argv[7]
seed = {"0.38": (16.29, 13.14), "0.19": (16.21, 13.28)}.get(cell)  # 004 Table 3: MPM2, MPM1
L, D = c["L"] * 1e3, c["D"] * 1e3
Ls, Ds = s["L"] * 1e3, s["D"] * 1e3
pct = lambda a, b: f"{100 * (a / b - 1):+.2f}%"
seed_cols = f"{seed[0]}, {seed[1]} | {pct(L, seed[0])} | {pct(D, seed[1])}" if seed else "- | - | -"
rng = f"{c['D_min'] * 1e3:.3f}-{c['D_max'] * 1e3:.3f}"
print(f"| {cell} | {c['particles']} | {steps} | {L:.3f} | {D:.3f} | {rng} | {c['D_radius'] * 1e3:.3f} | {Ls:.3f} | {Ds:.3f} | {pct(L, 16.2)} | {pct(D, 13.5)} | {seed_cols} | {t1 - t0:.1f} | {rate} |")
PY
  echo "cell $cell mm done" >&2
done
echo
cat "$table"
echo
echo "Experiment (Johnson & Holmquist 1988): L = 16.2 mm, D = 13.5 mm. L and D on particle centres;"
echo "D is the mean caliper width of the foot (hull perimeter / pi), with the narrowest and widest"
echo "widths by direction and twice the largest radius beside it;"
echo "'surf' adds half a particle spacing at the free end and at each side of the foot."
