#!/usr/bin/env bash
# V1 study: runs graded.toml, uniform_fine.toml and uniform_coarse.toml one after the other,
# extracts sigma_xx along the rod at 9, 18, 31 and 40 us (mpm-post profile), then analyse.py
# writes study/table.md and the plot data, and gnuplot draws study/profiles.png.
# Usage: ./study.sh BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")"
bin=$1
mkdir -p study
for case in graded uniform_fine uniform_coarse; do
  echo "running $case ..." >&2
  start=$(date +%s.%N)
  "$bin/mpm-prep/mpm-prep" $case.toml 2> study/prep_$case.log |
    "$bin/mpm-run/mpm-run" --stats --progress none 2> study/run_$case.log |
    "$bin/mpm-post/mpm-post" profile - --field sigma --component xx \
      --time 9us --time 18us --time 31us --time 40us -o study/$case.csv
  end=$(date +%s.%N)
  echo "$start $end" > study/wall_$case.txt
done
python3 analyse.py study
gnuplot profiles.gp
echo
cat study/table.md
echo "plot: study/profiles.png"
