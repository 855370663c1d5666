#!/usr/bin/env python3
"""Does qvr's fresh input buy it anything over sw? For each DIR (a claim_matrix.sh condition
with run1..run3, or one `qvr run` output folder) prints, for sw and qvr, the median absolute
error of the policy's headset-time prediction (t_local_pred_ms against the measured
headset_busy_ms), the median e1 it chose, and the median displayed FPS over the runs. Frames
before --warmup (default 10) are left out, as `qvr run` leaves them out of its statistics.

    python3 scripts/policy_inputs.py [--warmup N] DIR [DIR ...]
"""
import csv
import json
import os
import statistics
import sys


def usage(msg):
    print(f"policy_inputs.py: {msg}", file=sys.stderr)
    print("usage: policy_inputs.py [--warmup N] DIR [DIR ...]", file=sys.stderr)
    sys.exit(2)


def runs_of(d):
    runs = [os.path.join(d, f"run{k}") for k in (1, 2, 3)]
    runs = [r for r in runs if os.path.isdir(r)]
    return runs if runs else [d]


def main(argv):
    warmup = 10
    dirs = []
    i = 0
    while i < len(argv):
        if argv[i] == "--warmup":
            if i + 1 >= len(argv):
                usage("--warmup needs a number")
            try:
                warmup = int(argv[i + 1])
            except ValueError:
                usage(f"--warmup: not a number: {argv[i + 1]}")
            if warmup < 0:
                usage("--warmup must be ≥ 0")
            i += 2
            continue
        dirs.append(argv[i])
        i += 1
    if not dirs:
        usage("no folder given")
    print("| condition | sw error (ms) | qvr error (ms) | sw e1 | qvr e1 | sw FPS | qvr FPS |")
    print("|---|---|---|---|---|---|---|")
    shown = 0
    for d in dirs:
        if not os.path.isdir(d):
            usage(f"not a folder: {d}")
        cells = {}
        for design in ("sw", "qvr"):
            err, e1, fps = [], [], []
            for run in runs_of(d):
                frames = os.path.join(run, f"frames_{design}.csv")
                summary = os.path.join(run, "summary.json")
                if not os.path.exists(frames) or not os.path.exists(summary):
                    continue
                try:
                    with open(frames, newline="") as f:
                        for r in csv.DictReader(f):
                            if int(r["frame"]) < warmup:
                                continue
                            err.append(abs(float(r["t_local_pred_ms"]) -
                                           float(r["headset_busy_ms"])))
                            e1.append(float(r["e1_deg"]))
                    with open(summary) as f:
                        fps.append(float(json.load(f)["designs"][design]["fps_mean"]))
                except (KeyError, ValueError, json.JSONDecodeError) as e:
                    usage(f"{run}: not a qvr run output ({e})")
            if err:
                cells[design] = (statistics.median(err), statistics.median(e1),
                                 statistics.median(fps))
        if len(cells) != 2:
            print(f"policy_inputs.py: {d}: no sw and qvr frames, skipped", file=sys.stderr)
            continue
        (se, s1, sf), (qe, q1, qf) = cells["sw"], cells["qvr"]
        name = os.path.basename(os.path.normpath(d))
        print(f"| {name} | {se:.2f} | {qe:.2f} | {s1:.1f}° | {q1:.1f}° | {sf:.1f} | {qf:.1f} |")
        shown += 1
    return 0 if shown else 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
