#!/usr/bin/env bash
# V5's path study in axisymmetry (axisym.toml): 434 m/s (SPEED) through the plain slab with the
# path refined to each finest cell of PATHS (mm: 4 is scene.toml's level 2 alone, 2 adds a 2 mm
# level, 1 a 2 and a 1 mm level, 0.5 a third), the projectile at 4 particles a cell of the finest
# level (8 on the 4 mm path: 0.5 mm apart, as on the 2 mm path), started at each offset of SHIFTS
# (mm above the scene's start, 0.5 mm above the slab): near the ballistic limit one start against
# another moves the residual velocity by several percent (results.md), so each path's figure is
# the mean over the starts, with its standard deviation and the change of the mean from the
# coarser path. Writes study/axisym.md; the streams are deleted after each run.
# Usage: ./axisym.sh BUILD_DIR THREADS "4 2 1" "0 0.1 0.2 0.3" [SPEED]
set -euo pipefail
cd "$(dirname "$0")"
bin=$1 threads=$2 paths=$3 shifts=$4 speed=${5:-434}
mkdir -p study
# The levels for a path whose finest cell is p mm: 40 mm wide at p, each coarser level 8 mm wider.
levels() {
  case $1 in
    4) n=2 ;; 2) n=3 ;; 1) n=4 ;; 0.5) n=5 ;; 0.25) n=6 ;;
    *) echo "axisym.sh: a path's finest cell is 4, 2, 1, 0.5 or 0.25 (mm), not '$1'" >&2; exit 2 ;;
  esac
  local s="[{level = 2, min = \"0 -400 mm\", max = \"80 160 mm\"}"
  for ((l = 3; l <= n; ++l)); do
    s+=", {level = $l, min = \"0 -400 mm\", max = \"$((40 + 8 * (n - l))) 160 mm\"}"
  done
  echo "$s]"
}
rows=()
for p in $paths; do
  ppc=4
  [ "$p" = 4 ] && ppc=8
  for s in $shifts; do
    name=ax${p}_${s}_$speed
    y=$(awk -v s="$s" 'BEGIN { printf "%g", 144.2 + s }')  # axisym.toml's start, 144.2 mm
    echo "running $name ($(date +%H:%M:%S)) ..." >&2
    "$bin/mpm-prep/mpm-prep" axisym.toml --set "grid.levels=$(levels "$p")" \
      --set bodies.projectile.particles_per_cell=$ppc --set "bodies.projectile.translate=0 $y mm" \
      --set "bodies.projectile.velocity=0 -$speed m/s" \
      --set "scene.title=V5 axisymmetric, $speed m/s, path $p mm, start +$s mm" \
      -o study/$name.model 2> study/prep_$name.log
    status=0
    start=$(date +%s.%N)
    "$bin/mpm-run/mpm-run" study/$name.model -o study/$name.mpm --threads "$threads" \
      --progress none 2> study/run_$name.log || status=$?
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
    # A run stopped early (status 3) keeps its frames; mpm-post reads them and passes the status on.
    v=$({ "$bin/mpm-post/mpm-post" residual study/$name.mpm --body projectile --target slab \
      --json 2>> study/run_$name.log || true; } |
      python3 -c 'import json, sys; print("%.1f" % json.load(sys.stdin)["residual_velocity"])' 2>/dev/null ||
      echo nan)
    rows+=("$p $s $v $wall $status")
    rm -f study/$name.mpm study/$name.model
  done
done
printf '%s\n' "${rows[@]}" | python3 -c '
import statistics as st, sys
speed = sys.argv[1]
runs = [l.split() for l in sys.stdin if l.strip()]
print("# V5 in axisymmetry, %s m/s: the residual velocity along a refined path\n" % speed)
print("| path (finest cell, mm) | start (+mm) | v_r (m/s) | wall (s) | mpm-run status |")
print("|---|---|---|---|---|")
for p, s, v, w, status in runs:
    print("| %s | %s | %s | %s | %s |" % (p, s, v, w, status))
print("\n| path (mm) | runs | mean v_r (m/s) | standard deviation | change of the mean from the coarser path |")
print("|---|---|---|---|---|")
prev = None
for p in dict.fromkeys(r[0] for r in runs):
    vs = [float(r[2]) for r in runs if r[0] == p]
    m = st.mean(vs)
    sd = "%.1f" % st.stdev(vs) if len(vs) > 1 else ""
    ch = "%+.1f%%" % (100 * (m / prev - 1)) if prev else ""
    print("| %s | %d | %.1f | %s | %s |" % (p, len(vs), m, sd, ch))
    prev = m
print("\nA run whose mpm-run status is not 0 stopped early (its log: study/run_ax*.log); its v_r is that of its last frame.")
' "$speed" | tee study/axisym.md
