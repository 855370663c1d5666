#!/usr/bin/env python3
"""Each design's frame rate over the same stretch of a time-varying link.

`qvr run` gives every design the same number of frames, and each design's session replays the
link's trace from its start. On a trace whose rate falls away after a few seconds (Verizon-EVDO
drops from ~0.5 to ~0.03 Mbit/s after 8 s), a slow design runs into the bad stretch and a fast one
finishes before it: its frames-per-second is partly the trace's, not the design's. This script
counts, for every design of one `qvr run` folder (or every condition's first take in a
`qvr sweep` folder), the frames displayed after its warm-up (the first 10 frames, as `qvr run`'s
summary leaves out) up to T seconds into its session, T being the shortest session of that run,
over the time from its 10th displayed frame to T: every design ends on the same second of the
trace.

    scripts/sweep_window.py RUN_OR_SWEEP_DIR [--design qvr]

Per run: T, each design's window FPS and whole-session FPS (frames_<design>.csv's display_ns
from the first pose_ns, both after the warm-up), and the design's window FPS over
the best fixed design's (ffr counts as fixed:5). Exit 2 on a folder with no frames_*.csv.
"""
import argparse
import csv
import glob
import os
import sys

WARMUP = 10  # qvr run's --warmup-frames default


def session(path):
    """(first pose ns, sorted display ns) of one design's frames file."""
    poses, shown = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row.get("pose_ns") not in (None, "", "0"):
                poses.append(int(row["pose_ns"]))
            if row.get("display_ns") not in (None, "", "0"):
                shown.append(int(row["display_ns"]))
    if not poses or not shown:
        return None
    return min(poses), sorted(shown)


def is_fixed(design):
    return design == "ffr" or design.startswith("fixed:")


def window_rates(run_dir):
    sessions = {}
    for path in glob.glob(os.path.join(run_dir, "frames_*.csv")):
        s = session(path)
        if s:
            sessions[os.path.basename(path)[len("frames_"):-len(".csv")]] = s
    if not sessions:
        return None
    window_s = min((shown[-1] - t0) for t0, shown in sessions.values()) / 1e9
    rates = {}
    for design, (t0, shown) in sessions.items():
        if len(shown) <= WARMUP + 1:
            continue
        start = shown[WARMUP - 1]
        end = t0 + window_s * 1e9
        in_window = sum(1 for t in shown[WARMUP:] if t <= end)
        window_rate = in_window / ((end - start) / 1e9) if end > start else 0.0
        rates[design] = (window_rate, (len(shown) - WARMUP) / ((shown[-1] - start) / 1e9))
    return (window_s, rates) if rates else None


def report(run_dir, focus):
    got = window_rates(run_dir)
    if got is None:
        return False
    window_s, rates = got
    fixed = {d: r for d, r in rates.items() if is_fixed(d)}
    best_w = max(fixed, key=lambda d: fixed[d][0]) if fixed else None
    best_s = max(fixed, key=lambda d: fixed[d][1]) if fixed else None
    line = f"{os.path.basename(os.path.normpath(run_dir))}: window {window_s:.2f} s"
    if focus in rates and best_w:
        line += (f" | {focus}/best fixed: window {rates[focus][0] / fixed[best_w][0]:.2f} "
                 f"({best_w}), whole session {rates[focus][1] / fixed[best_s][1]:.2f} ({best_s})")
    print(line)
    for design, (w, s) in sorted(rates.items(), key=lambda kv: -kv[1][0]):
        print(f"  {design:10s} window {w:6.1f} FPS   whole session {s:6.1f} FPS")
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--design", default="qvr")
    a = ap.parse_args()
    runs = sorted(glob.glob(os.path.join(a.dir, "c*_grid")))
    if not runs:
        runs = [a.dir]
    shown = sum(report(r, a.design) for r in runs)
    if shown == 0:
        print(f"sweep_window: no frames_*.csv with displayed frames under {a.dir}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
