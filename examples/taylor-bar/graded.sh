#!/usr/bin/env bash
# Graded-grid Taylor bar (V2, 004 section 5.2): graded.toml (0.19 mm by the wall, 0.38 mm
# elsewhere) against uniform 0.19 mm and uniform 0.38 mm grids, run one after the other on the
# same machine: L and D (particle centres), particles at the start and the end, steps, wall
# time; study/graded_table.md and study/cost_error.png.
# Usage: ./graded.sh BUILD_DIR [THREADS]
set -euo pipefail
cd "$(dirname "$0")"
bin=$1
threads=${2:-2}
mkdir -p study
run_case() {  # name, then mpm-prep arguments
  local name=$1; shift
  echo "running $name ..." >&2
  "$bin/mpm-prep/mpm-prep" "$@" -o study/$name.model 2> study/prep_$name.log
  local start end
  start=$(date +%s.%N)
  "$bin/mpm-run/mpm-run" study/$name.model -o study/$name.mpm --threads "$threads" --stats \
    --progress none 2> study/run_$name.log
  end=$(date +%s.%N)
  echo "$start $end" > study/wall_$name.txt
  "$bin/mpm-post/mpm-post" taylor study/$name.mpm --json > study/taylor_$name.json
  rm -f study/$name.model
}
run_case graded graded.toml
run_case uniform_038 scene.toml --set grid.cell_size="0.38 mm"
run_case uniform_019 scene.toml --set grid.cell_size="0.19 mm"
python3 graded_table.py study
gnuplot cost_error.gp
echo
cat study/graded_table.md
echo "plot: study/cost_error.png"
