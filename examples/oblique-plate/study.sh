#!/usr/bin/env bash
# V6 study: each striking speed on the graded grid of scene.toml (004: 2 mm level 1, 1 mm level 2
# over the path) and on the uniform 1 mm grid, one run after the other on the same machine; the
# residual velocity (mpm-post residual), steps, wall time and throughput (mpm-run --stats) of
# each go to study/table.md (table.py).
# Usage: ./study.sh BUILD_DIR THREADS "446 575 730" "graded uniform" [END_TIME [DIR]]
# Grids: graded (scene.toml), graded3 (with a 0.5 mm third level over the path), uniform (1 mm).
# END_TIME (e.g. 60us) cuts every run short (a cost comparison, not a residual velocity); DIR
# is the output directory (default study).
set -euo pipefail
cd "$(dirname "$0")"
bin=$1 threads=$2 speeds=$3 grids=$4 end=${5:-} study=${6:-study}
mkdir -p "$study"
# graded3's boxes: scene.toml's level 2 and a level 3 inside it.
level2='{level=2, min="0 -38 -40 mm", max="24 10 14 mm"}'
level3='{level=3, min="0 -26 -30 mm", max="10 8 4 mm"}'
# 004 Table 9's end times; the rod flies along (0, -sin 30, -cos 30).
end_time() {
  if [ -n "$end" ]; then echo "$end"; return; fi
  case $1 in 446) echo 0.4ms ;; 575) echo 0.3ms ;; 730) echo 0.21ms ;; *) echo 0.3ms ;; esac
}
for v in $speeds; do
  vel=$(python3 -c "import math; v=$v; print(f'0 {-v*0.5:.4f} {-v*math.cos(math.pi/6):.4f} m/s')")
  for g in $grids; do
    name=${g}_$v
    case $g in
      graded) grid=() ;;
      # The seed's two levels and a third (0.5 mm) over the path through the plate, 1 mm inside
      # level 2's box (the nesting rule) and 10 mm across from the symmetry plane: the rod's
      # 6.45 mm radius and the hole's lip (results.md, "A third level").
      graded3) grid=(--set "grid.levels=[$level2, $level3]") ;;
      uniform) grid=(--set 'grid.levels=[]' --set grid.cell_size=1mm) ;;
      *) echo "study.sh: unknown grid '$g' (graded, graded3 or uniform)" >&2; exit 2 ;;
    esac
    echo "running $name ($(date +%H:%M:%S)) ..." >&2
    "$bin/mpm-prep/mpm-prep" scene.toml "${grid[@]}" --set "bodies.projectile.velocity=$vel" \
      --set "solver.end_time=$(end_time "$v")" --set "scene.title=V6 $v m/s, $g" \
      -o "$study"/$name.model 2> "$study"/prep_$name.log
    status=0
    "$bin/mpm-run/mpm-run" "$study"/$name.model -o "$study"/$name.mpm --threads "$threads" --stats \
      --progress none 2> "$study"/run_$name.log || status=$?
    echo "$status" > "$study"/status_$name.txt
    rm -f "$study"/$name.model
    "$bin/mpm-post/mpm-post" residual "$study"/$name.mpm --body projectile --target plate --json \
      > "$study"/residual_$name.json 2> "$study"/residual_$name.log || true
    if [ "$g" != uniform ]; then
      case $g in
        graded) picture=section_$v.png cells="2 mm / 1 mm" ;;
        graded3) picture=section_graded3_$v.png cells="2 mm / 1 mm / 0.5 mm" ;;
      esac
      "$bin/mpm-post/mpm-post" render "$study"/$name.mpm -o "$study"/$picture --view symmetry \
        --field eps_p --size 900x700 \
        --title "V6 at $v m/s, graded $cells: section through the path (x = 0)" || true
    fi
  done
done
python3 table.py "$study"
cat "$study/table.md"
