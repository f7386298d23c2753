#!/usr/bin/env bash
# Runs the V3 Taylor bar benchmark at 1 and 2 threads and prints a summary table.
# Usage: bench.sh BUILD_DIR [CELL] (CELL default 0.335 mm: model 2).
set -euo pipefail
cd "$(dirname "$0")"
bin=$1
cell=${2:-0.335 mm}
mkdir -p out
"$bin/mpm-prep/mpm-prep" taylor_v3.toml --set grid.cell_size="$cell" -o out/v3.model
echo
printf "%-8s %12s %8s %12s %14s %12s %10s\n" threads particles steps "wall s" "Mpart-steps/s" "peak MB" "B/particle"
for t in 1 2; do
  "$bin/mpm-run/mpm-run" out/v3.model -o /dev/null --threads "$t" --stats --progress none 2> out/run_$t.log
  line=$(grep "million particle-steps/s" out/run_$t.log)
  mem=$(grep "peak memory" out/run_$t.log)
  n=$(echo "$line" | sed -E 's/.*particles ([0-9]+).*/\1/')
  steps=$(echo "$line" | sed -E 's/.*steps ([0-9]+), sorts.*/\1/')
  rate=$(echo "$line" | sed -E 's/.* ([0-9.]+) million particle-steps\/s/\1/')
  wall=$(grep "^total" out/run_$t.log | awk '{print $2}')
  peak=$(echo "$mem" | sed -E 's/peak memory ([0-9.]+) MB.*/\1/')
  bpp=$(echo "$mem" | sed -E 's/.*MB, ([0-9]+) bytes per particle.*/\1/')
  printf "%-8s %12s %8s %12s %14s %12s %10s\n" "$t" "$n" "$steps" "$wall" "$rate" "$peak" "$bpp"
  eval "rate_$t=$rate"
done
echo
echo "speed-up 2/1 threads: $(echo "scale=3; $rate_2 / $rate_1" | bc)  parallel efficiency: $(echo "scale=3; $rate_2 / $rate_1 / 2" | bc)"
for t in 1 2; do
  echo
  echo "kernel times, $t thread(s):"
  sed -n '/^kernel/,/^total/p' out/run_$t.log
done
