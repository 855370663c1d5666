#!/usr/bin/env bash
# scripts/move_bytes.py on a made-up sweep folder: a fixed grid whose bytes fall with e1 and a
# design that holds at 8° (as the grid there), moves to 6° (1.5x the grid there) and sends one
# key frame; the script must split the three, and refuse a folder with nothing to read (exit 2).
set -euo pipefail
script="$(cd "$(dirname "$0")/../.." && pwd)/scripts/move_bytes.py"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import json, os, sys
d = sys.argv[1]
os.makedirs(f"{d}/c01_grid"); os.makedirs(f"{d}/c01_r2")
json.dump({"designs": {"fixed:6": {"e1_deg_mean": 6, "bytes_per_frame_mean": 3000},
                       "fixed:8": {"e1_deg_mean": 8, "bytes_per_frame_mean": 2000},
                       "qvr": {"e1_deg_mean": 8, "bytes_per_frame_mean": 2000}}},
          open(f"{d}/c01_grid/summary.json", "w"))
rows = [(8.0, 2000)] * 30 + [(6.0, 4500)] + [(6.0, 30000)] + [(6.0, 3000)] * 20
with open(f"{d}/c01_r2/frames_qvr.csv", "w") as f:
    f.write("design,frame,e1_deg,bytes\n")
    for i, (e, b) in enumerate(rows):
        f.write(f"qvr,{i},{e},{b}\n")
PY
out=$(python3 "$script" "$dir")
echo "$out"
grep -Eq "held +39 frames +1\.00x" <<<"$out"
grep -Eq "moved +1 frames +1\.50x" <<<"$out"
grep -Eq "spike +1 frames +10\.00x" <<<"$out"
grep -q "spikes: 1, 1 of them on or one frame after a move down" <<<"$out"
# A frames file without its columns is named and left out: nothing left to read is exit 2.
mkdir -p "$dir/bad/c01_grid" "$dir/bad/c01_r2"
cp "$dir/c01_grid/summary.json" "$dir/bad/c01_grid/"
{ echo "design,frame"; for i in $(seq 0 19); do echo "qvr,$i"; done; } >"$dir/bad/c01_r2/frames_qvr.csv"
set +e
err=$(python3 "$script" "$dir/bad" 2>&1 >/dev/null)
rc=$?
set -e
grep -q "not a frames file" <<<"$err" || { echo "no message for a bad frames file: $err"; exit 1; }
[ "$rc" = 2 ] || { echo "expected exit 2 with no readable frames, got $rc"; exit 1; }
mkdir "$dir/empty"
set +e
python3 "$script" "$dir/empty" 2>/dev/null
rc=$?
set -e
[ "$rc" = 2 ] || { echo "expected exit 2 on an empty folder, got $rc"; exit 1; }
echo "move_bytes_test: ok"
