#!/usr/bin/env bash
# Kills a real run with SIGKILL mid-run, continues it with `mpm-run --restart`, and compares it
# with the run that was never stopped: the whole result file (cmp) and, against a run without
# checkpoints, every frame (FRAM records byte for byte).
#
#   tests/tools/restart_check.sh SCENE EVERY [BUILD] [THREADS]
#   tests/tools/restart_check.sh examples/taylor-bar/scene.toml "10 us"
#   tests/tools/restart_check.sh examples/hypervelocity/scene.toml "5 us"
#
# EVERY is output.checkpoint.time; the kill comes 0.5 s after the first checkpoint is in the
# file (so in the middle of a later record). Exit 0 when everything is bitwise equal.
set -euo pipefail
scene=$1
every=$2
build=${3:-build}
threads=${4:-2}
prep=$build/mpm-prep/mpm-prep
runner=$build/mpm-run/mpm-run
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$prep" "$scene" -o "$work/plain_model.mpm" 2>/dev/null
"$prep" "$scene" --set "output.checkpoint.time=$every" -o "$work/model.mpm" 2>/dev/null
run() { "$runner" "$1" --threads "$threads" --progress none -o "$2" 2>"$work/err.txt"; }

start=$(date +%s.%N)
run "$work/plain_model.mpm" "$work/plain.mpm"
plain_s=$(echo "$(date +%s.%N) - $start" | bc)
start=$(date +%s.%N)
run "$work/model.mpm" "$work/full.mpm"
full_s=$(echo "$(date +%s.%N) - $start" | bc)

# The run to kill: SIGKILL half a second after its first checkpoint reached the file. Started
# as a plain command (not through the function), so that $! is mpm-run itself.
"$runner" "$work/model.mpm" --threads "$threads" --progress none -o "$work/killed.mpm" \
  2>"$work/killed_err.txt" &
pid=$!
while [ "$(grep -a -o CHKP "$work/killed.mpm" 2>/dev/null | wc -l)" -lt 1 ]; do
  kill -0 $pid 2>/dev/null || { echo "the run ended before its first checkpoint" >&2; exit 1; }
  sleep 0.05
done
sleep 0.5
kill -KILL $pid
wait $pid && { echo "the run completed before the kill" >&2; exit 1; } || status=$?
pgrep -f -- "-o $work/killed.mpm" >/dev/null && { echo "the killed run is still alive" >&2; exit 1; }
killed_bytes=$(stat -c %s "$work/killed.mpm")
start=$(date +%s.%N)
"$runner" --restart "$work/killed.mpm" --threads "$threads" --progress none 2>"$work/restart.txt"
restart_s=$(echo "$(date +%s.%N) - $start" | bc)

frames() {  # md5 of each FRAM record
  python3 - "$1" <<'PY'
import hashlib, struct, sys
b = open(sys.argv[1], 'rb').read()
o = 16
while o + 12 <= len(b):
    t, n = b[o:o + 4], struct.unpack('<Q', b[o + 4:o + 12])[0]
    if t == b'FRAM':
        print(hashlib.md5(b[o:o + 16 + n]).hexdigest())
    o += 16 + n
PY
}
echo "scene: $scene (checkpoint every $every, $threads threads)"
echo "run without checkpoints: ${plain_s} s; with: ${full_s} s ($(grep -a -o CHKP "$work/full.mpm" | wc -l) checkpoints, $(stat -c %s "$work/full.mpm") bytes against $(stat -c %s "$work/plain.mpm"))"
echo "killed (status $status) at $killed_bytes bytes; restart: ${restart_s} s"
sed 's/^/  /' "$work/restart.txt"
ok=0
if cmp -s "$work/killed.mpm" "$work/full.mpm"; then
  echo "restarted file = uninterrupted file, byte for byte ($(md5sum <"$work/full.mpm" | cut -c1-32))"
else
  echo "restarted file DIFFERS from the uninterrupted one: $(cmp "$work/killed.mpm" "$work/full.mpm" || true)"
  ok=1
fi
if [ "$(frames "$work/killed.mpm")" = "$(frames "$work/plain.mpm")" ]; then
  echo "its $(frames "$work/plain.mpm" | wc -l) frames = the frames of the run without checkpoints, bitwise"
else
  echo "frames DIFFER from the run without checkpoints"
  ok=1
fi
exit $ok
