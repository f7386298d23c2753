#!/usr/bin/env bash
# V5 study: the four striking speeds of 004 Table 5 at the level-1 cell CELL (level 2 half of
# it), and 749 m/s at each cell of CELLS (the resolution study), one run after the other; the
# residual velocity (mpm-post residual), steps, wall time and throughput (mpm-run --stats) of
# each go to study/table.md (table.py), with the change of each speed's residual velocity from
# one cell to the next finer one that ran (the convergence check: `make converge` runs the four
# speeds at 6 mm into the same folder).
# PLACE=mid (a sixth argument; `make placement`) lowers the domain's floor by half a level-2 cell,
# so that the slab's struck face lies midway between level 2's node planes instead of on one:
# cases c<cell>_<v>_mid, and table.md gives each speed's change between the two placements.
# rate (`make tension`): the concrete's tensile strength rises with the strain rate
# (materials.concrete.strength.tension_rate = "malvar-ross", docs/scene.md): cases
# c<cell>_<v>_rate, and table.md gives each speed's change from HJC as published.
# friction (`make friction`): Coulomb friction FRICTION (default 0.1) between projectile and
# slab instead of none: cases c<cell>_<v>_friction; rate-friction both changes at once: cases
# c<cell>_<v>_rate-friction. table.md gives each speed's change from the scene as it is.
# Usage: ./study.sh BUILD_DIR THREADS "434 606 749 1058" CELL "16mm 10mm 8mm"
#          [node|mid|rate|friction|rate-friction]
set -euo pipefail
cd "$(dirname "$0")"
bin=$1 threads=$2 speeds=$3 cell=$4 cells=$5 place=${6:-node}
extra=()
case $place in
  node) suffix= ;;
  mid) suffix=_mid ;;
  rate) suffix=_rate extra=(--set materials.concrete.strength.tension_rate=malvar-ross) ;;
  friction) suffix=_friction extra=(--set "contact.0.friction=${FRICTION:-0.1}") ;;
  rate-friction)
    suffix=_rate-friction
    extra=(--set materials.concrete.strength.tension_rate=malvar-ross
      --set "contact.0.friction=${FRICTION:-0.1}") ;;
  *)
    echo "study.sh: the variant is node, mid, rate, friction or rate-friction, not '$place'" >&2
    exit 2 ;;
esac
mkdir -p study
# 004 Table 5's end times.
end_time() { case $1 in 434) echo 2ms ;; 606) echo 0.6ms ;; 749) echo 0.5ms ;; 1058) echo 0.3ms ;; *) echo 0.5ms ;; esac; }
cases=()
for v in $speeds; do cases+=("$cell:$v"); done
for c in $cells; do
  [ "$c" = "$cell" ] && [[ " $speeds " == *" 749 "* ]] && continue
  cases+=("$c:749")
done
# The domain's floor at the first multiple of the level-1 cell C at or below z = -400 mm, so that
# the node planes of both levels pass through z = 0, the slab's struck face, at every C (-402 mm
# at 6 mm): with the face inside a cell 434 m/s reads 9% lower at 6 mm (results.md, 2026-11-27
# morning). The level-2 box on that lattice: the scene's 80 mm x 80 mm quarter region widened to
# whole cells (84 mm at 6 mm), over the whole height of the domain (the whole cells up to 160 mm:
# 156 mm at 6 mm). At 16, 10, 8 and 5 mm the floor is -400 mm and the box the scene's.
# PLACE=mid: a quarter of the level-1 cell lower (half a level-2 cell).
floor_z() {
  awk -v c="${1%mm}" -v mid="$([ "$place" = mid ] && echo 1 || echo 0)" \
    'BEGIN { printf "%g", -c * int(400 / c + 1 - 1e-9) - mid * c / 4 }'
}
level_box() {
  awk -v c="${1%mm}" -v f="$(floor_z "$1")" 'BEGIN { x = c * int((80 + c - 1e-9) / c);
    z = f + c * int((160 - f) / c + 1e-9); printf "%g %g %g mm", x, x, z }'
}
for cv in "${cases[@]}"; do
  c=${cv%%:*} v=${cv##*:}
  name=c${c%mm}_$v$suffix
  echo "running $name ($(date +%H:%M:%S)) ..." >&2
  "$bin/mpm-prep/mpm-prep" scene.toml --set grid.cell_size="$c" \
    --set "grid.domain.min=0 0 $(floor_z "$c") mm" --set "grid.levels.0.min=0 0 $(floor_z "$c") mm" \
    --set "grid.levels.0.max=$(level_box "$c")" \
    --set "bodies.projectile.velocity=0 0 -$v m/s" --set "solver.end_time=$(end_time "$v")" \
    --set "scene.title=V5 $v m/s, level 1 $c${suffix:+, ${place}}" "${extra[@]}" \
    -o study/$name.model 2> study/prep_$name.log
  status=0
  "$bin/mpm-run/mpm-run" study/$name.model -o study/$name.mpm --threads "$threads" --stats \
    --progress none 2> study/run_$name.log || status=$?
  echo "$status" > study/status_$name.txt
  rm -f study/$name.model
  "$bin/mpm-post/mpm-post" residual study/$name.mpm --body projectile --target slab --json \
    > study/residual_$name.json 2> study/residual_$name.log || true
  "$bin/mpm-post/mpm-post" render study/$name.mpm -o study/damage_$name.png --view symmetry \
    --field damage --size 900x700 \
    --title "V5 at $v m/s, $c / level 2 half: damage at y = 0, rebar in red" || true
done
python3 table.py study
cat study/table.md
