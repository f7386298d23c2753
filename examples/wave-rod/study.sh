#!/usr/bin/env bash
# V1 study: runs graded.toml, uniform_fine.toml and uniform_coarse.toml one after the other,
# extracts sigma_xx along the rod at 9, 18, 31 and 40 us (mpm-post profile), then analyse.py
# writes study/table.md and the plot data, and gnuplot draws study/profiles.png.
# Usage: ./study.sh BUILD_DIR [SCHEME]   (SCHEME: USF, USL or MUSL; default the scenes' MUSL;
#        results of another scheme go to study-<scheme>/)
set -euo pipefail
cd "$(dirname "$0")"
bin=$1
scheme=${2:-}
dir=study
sets=()
if [ -n "$scheme" ]; then
  dir=study-$(echo "$scheme" | tr 'A-Z' 'a-z')
  sets=(--set "solver.scheme=$scheme")
fi
mkdir -p "$dir"
for case in graded uniform_fine uniform_coarse; do
  echo "running $case ..." >&2
  start=$(date +%s.%N)
  "$bin/mpm-prep/mpm-prep" $case.toml "${sets[@]}" 2> "$dir/prep_$case.log" |
    "$bin/mpm-run/mpm-run" --stats --progress none 2> "$dir/run_$case.log" |
    "$bin/mpm-post/mpm-post" profile - --field sigma --component xx \
      --time 9us --time 18us --time 31us --time 40us -o "$dir/$case.csv"
  end=$(date +%s.%N)
  echo "$start $end" > "$dir/wall_$case.txt"
done
python3 analyse.py "$dir"
gnuplot -e "dir='$dir'; scheme='${scheme:-MUSL}'" profiles.gp
echo
cat "$dir/table.md"
echo "plot: $dir/profiles.png"
