#!/usr/bin/env bash
# Runs V4 variants and appends a row per variant to out/table.md: particles, cells, steps,
# wall time, throughput, peak memory, and the debris front and width at 30.6 us (99.5th
# percentile, with the maxima) against the experiment (200 mm, 145 mm). Also a side-view PNG.
# Usage: ./study.sh BUILD_DIR VARIANT...   (coarse, small-1.06, small-1.59, small-2.12, large,
#        axi-H: axisym.toml at H mm cells, 2 particles per cell, e.g. axi-0.265;
#        till-VARIANT: VARIANT with lead's Tillotson EOS, docs/eos-tillotson.md, e.g.
#        till-axi-0.265). THREADS=N sets mpm-run's threads (default 2).
set -euo pipefail
cd "$(dirname "$0")"
bin=$1; shift
mkdir -p out
table=out/table.md
[ -f "$table" ] || {
  echo "| variant | particles | cell mm | spacing mm | steps | wall s | Mpart-steps/s | peak MB | front p99.5 mm | width p99.5 mm | front max mm | width max mm | front vs exp | width vs exp |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
} > "$table"
# Lead's Tillotson constants as derived in docs/eos-tillotson.md (before any V4 run with them).
tillotson='materials.lead.eos={ model = "tillotson", a = 0.5, b = 2.27, A = "47.7 GPa", B = "25.5 GPa", E0 = "0.942 MJ/kg", E_iv = "0.264 MJ/kg", E_cv = "1.130 MJ/kg", alpha = 5, beta = 5 }'
for variant in "$@"; do
  sets=()
  frames=6
  scene=scene.toml
  base=${variant#till-}
  case $base in
    coarse) ;;
    small-*)
      cell=${base#small-}
      n=$(python3 -c "print(round($cell / 0.53))")
      sets=(--set "grid.cell_size=$cell mm" --set "bodies.plate.particles_per_cell=$n"
            --set "bodies.sphere.particles_per_cell=$n" --set 'bodies.plate.size=6.36 140 140 mm') ;;
    large)
      frames=2
      # The seed's large model: 0.21 mm spacing in 1 mm cells (4.76 particles per cell along
      # each axis, so the spacing is the bodies' own, not cell_size / particles_per_cell).
      sets=(--set 'grid.cell_size=1 mm' --set 'bodies.plate.particle_spacing=0.21 mm'
            --set 'bodies.sphere.particle_spacing=0.21 mm' --set 'bodies.plate.size=6.36 140 140 mm'
            --set 'grid.domain={ min = "-51 -83 -83 mm", max = "249 83 83 mm" }'
            --set output.precision=float32) ;;
    axi-*)
      scene=axisym.toml
      sets=(--set "grid.cell_size=${base#axi-} mm") ;;
    *) echo "unknown variant $variant" >&2; exit 2 ;;
  esac
  [ "$base" = "$variant" ] || sets+=(--set "$tillotson")
  out=out/$variant.mpm
  start=$(date +%s.%N)
  "$bin/mpm-prep/mpm-prep" "$scene" "${sets[@]}" --set output.frames=$frames 2> out/prep_$variant.log |
    "$bin/mpm-run/mpm-run" --threads "${THREADS:-2}" --stats --progress lines -o "$out" 2> out/run_$variant.log
  end=$(date +%s.%N)
  "$bin/mpm-post/mpm-post" debris "$out" --time "30.6 us" --expect-front "200 mm" --expect-width "145 mm" | tee out/debris_$variant.txt
  json=$("$bin/mpm-post/mpm-post" debris "$out" --time "30.6 us" --json)
  "$bin/mpm-post/mpm-post" render "$out" --time "30.6 us" -o "out/$variant.png" --field speed --view side \
    --title "V4 $variant: debris cloud at 30.6 us, coloured by speed (m/s)" --size 1600x900
  python3 - "$variant" "$json" "$start" "$end" out/run_$variant.log out/prep_$variant.log >> "$table" <<'PY'
import json, re, sys
variant, d, t0, t1, runlog, preplog = sys.argv[1], json.loads(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5], sys.argv[6]
run, prep = open(runlog).read(), open(preplog).read()
m = re.search(r"particles (\d+), steps (\d+), sorts \d+, particle-steps [0-9.e+]+, ([0-9.]+) million", run)
peak = re.search(r"peak memory ([0-9.]+) MB", run).group(1)
cell = re.search(r"cell ([0-9.]+) mm", prep).group(1)
spacing = re.search(r"plate\s+lead\s+\d+\s+([0-9.]+) mm", prep).group(1)
total = re.search(r"total\s+(\d+)", prep).group(1)
mm = lambda v: f"{1e3 * v:.1f}"
print(f"| {variant} | {total} | {cell} | {spacing} | {m.group(2)} | {t1 - t0:.0f} | {m.group(3)} | {peak} | {mm(d['front'])} | {mm(d['width'])} | {mm(d['front_max'])} | {mm(d['width_max'])} | {100 * (d['front'] / 0.2 - 1):+.1f}% | {100 * (d['width'] / 0.145 - 1):+.1f}% |")
PY
done
cat "$table"
