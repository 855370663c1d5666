#!/usr/bin/env python3
"""What moving e1 costs an adaptive design in bytes, read from `qvr sweep` folders.

A fixed design's layers keep their size, so its encoders code P-frames of the same canvas. An
adaptive design that moves e1 resamples its layers (P-frames predict less) and, moving down, can
outgrow its canvas (a key frame). This script compares, for every condition of each sweep
folder, the design's bytes per frame with the fixed grid's bytes at the same e1 (the condition's
grid take, `summary.json`'s `fixed:E` and `ffr` means, interpolated in e1), by kind of frame:

- held:  e1 as the previous frame's, not a spike;
- moved: e1 differs from the previous frame's, not a spike;
- spike: more than 3x the run's median bytes (a key frame).

It also counts each design's spikes and how many came on or one frame after a move down.

    scripts/move_bytes.py SWEEP_DIR [SWEEP_DIR ...] [--design qvr]

Frames after the first 10 (qvr run's warm-up) of every take's frames_<design>.csv. A file that
does not read is named and left out; exit 2 when no condition has both a grid take and frames.
"""
import argparse
import csv
import glob
import json
import os
import statistics
import sys

WARMUP = 10  # qvr run's --warmup-frames default
SPIKE = 3.0  # a frame over this many times the run's median bytes is counted as a spike


def fixed_curve(grid_summary):
    """(e1, bytes per frame) of the fixed designs of a grid take, sorted by e1."""
    with open(grid_summary) as f:
        designs = json.load(f).get("designs", {})
    pts = [(d["e1_deg_mean"], d["bytes_per_frame_mean"]) for name, d in designs.items()
           if isinstance(d, dict) and (name.startswith("fixed:") or name == "ffr")
           and "e1_deg_mean" in d and "bytes_per_frame_mean" in d]
    return sorted(pts)


def at(curve, e1):
    """The curve's bytes at e1, linear between points, flat past its ends."""
    if e1 <= curve[0][0]:
        return curve[0][1]
    for (x0, y0), (x1, y1) in zip(curve, curve[1:]):
        if e1 <= x1:
            return y0 + (y1 - y0) * (e1 - x0) / (x1 - x0) if x1 > x0 else y1
    return curve[-1][1]


def frames(path):
    """(e1, bytes) of one frames_<design>.csv after the warm-up."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))[WARMUP:]
    return [(float(r["e1_deg"]), float(r["bytes"])) for r in rows]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("sweeps", nargs="+")
    ap.add_argument("--design", default="qvr")
    a = ap.parse_args()
    kinds = {k: [0.0, 0.0, 0] for k in ("held", "moved", "spike")}  # bytes, fixed bytes, frames
    spikes = after_down = conditions = 0
    for sweep in a.sweeps:
        for grid in sorted(glob.glob(os.path.join(sweep, "c*_grid", "summary.json"))):
            try:
                curve = fixed_curve(grid)
            except (OSError, ValueError) as e:
                print(f"move_bytes: {grid}: {e}", file=sys.stderr)
                continue
            if len(curve) < 2:
                continue
            cond = os.path.basename(os.path.dirname(grid)).split("_")[0]
            runs = glob.glob(os.path.join(sweep, f"{cond}_*", f"frames_{a.design}.csv"))
            counted = False
            for run in sorted(runs):
                try:
                    fr = frames(run)
                except (OSError, KeyError, ValueError) as e:
                    print(f"move_bytes: {run}: not a frames file ({e!r})", file=sys.stderr)
                    continue
                if len(fr) < 2:
                    continue
                counted = True
                median = statistics.median(b for _, b in fr)
                for i in range(1, len(fr)):
                    e1, b = fr[i]
                    spike = median > 0 and b > SPIKE * median
                    kind = "spike" if spike else "moved" if abs(e1 - fr[i - 1][0]) > 0.01 \
                        else "held"
                    k = kinds[kind]
                    k[0] += b
                    k[1] += at(curve, e1)
                    k[2] += 1
                    if spike:
                        spikes += 1
                        if any(j >= 1 and fr[j][0] < fr[j - 1][0] - 0.01 for j in (i, i - 1)):
                            after_down += 1
            conditions += 1 if counted else 0
    if conditions == 0:
        print(f"move_bytes: no condition with a grid take and a readable frames_{a.design}.csv in "
              f"{', '.join(a.sweeps)}", file=sys.stderr)
        return 2
    total = sum(k[0] for k in kinds.values())
    total_fixed = sum(k[1] for k in kinds.values())
    print(f"{a.design} over {conditions} conditions: bytes / the fixed grid's at the same e1")
    for name, (b, fb, n) in kinds.items():
        if n:
            print(f"  {name:5} {n:6} frames  {b / fb:5.2f}x  {100 * b / total:5.1f}% of its bytes")
    print(f"  all   {sum(k[2] for k in kinds.values()):6} frames  {total / total_fixed:5.2f}x")
    print(f"  spikes: {spikes}, {after_down} of them on or one frame after a move down")
    return 0


if __name__ == "__main__":
    sys.exit(main())
