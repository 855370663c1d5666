#!/usr/bin/env python3
"""Reads claim_matrix.sh's runs and writes matrix.md / matrix.json: per condition the median
over three runs of displayed FPS (with min-max) and MTP p99 for ffr, sw, qvr and the best fixed
e1 (chosen from run 1's sweep), and the ratios; the table shows qvr's and the best fixed e1's."""
import json
import os
import statistics
import sys

if len(sys.argv) != 2 or not os.path.isdir(sys.argv[1]):
    print("usage: claim_matrix_table.py OUT (the folder claim_matrix.sh wrote)", file=sys.stderr)
    sys.exit(2)
out = sys.argv[1]
rows = []
for name in sorted(os.listdir(out)):
    cdir = os.path.join(out, name)
    if not os.path.isdir(cdir):
        continue
    runs = []
    for rep in (1, 2, 3):
        p = os.path.join(cdir, f"run{rep}", "summary.json")
        if os.path.exists(p):
            runs.append(json.load(open(p)))
    if not runs:
        continue
    first = runs[0]
    best = first["best_fixed"]["design"]
    sweep = {d: v["fps_mean"] for d, v in first["designs"].items() if d.startswith("fixed:")}

    def fps_series(design):
        out_vals = []
        for r in runs:
            d = r["designs"]
            if design in d:
                out_vals.append(d[design])
            elif design == "fixed:5" and "ffr" in d:
                out_vals.append(d["ffr"])
        return out_vals

    entry = {"condition": name, "command": first["command"], "best_fixed": best, "sweep_fps": sweep}
    for design in ("ffr", "sw", "qvr", best):
        series = fps_series(design)
        if design == "ffr":
            series = [r["designs"]["ffr"] for r in runs if "ffr" in r["designs"]] + \
                     ([first["designs"]["fixed:5"]] if "fixed:5" in first["designs"] else [])
        fps = [s["fps_mean"] for s in series]
        p99 = [s["mtp_ms_p99"] for s in series]
        reused = [s["frames_reused"] / max(1, s["frames_displayed"]) for s in series]
        # Frames shown on time: displayed frames per second that were not re-warps of older ones.
        fresh = [s["fps_mean"] * (1.0 - s["frames_reused"] / max(1, s["frames_displayed"]))
                 for s in series]
        entry[design] = {"fps": fps, "mtp_p99": p99, "reused": reused, "fresh_fps": fresh,
                         "fresh_fps_median": statistics.median(fresh) if fresh else None,
                         "fps_median": statistics.median(fps) if fps else None,
                         "mtp_p99_median": statistics.median(p99) if p99 else None}
    q, f, b, s = entry["qvr"], entry["ffr"], entry[best], entry["sw"]
    entry["qvr_over_ffr"] = q["fps_median"] / f["fps_median"]
    entry["qvr_over_ffr_fresh"] = q["fresh_fps_median"] / max(1e-9, f["fresh_fps_median"])
    entry["qvr_over_best"] = q["fps_median"] / b["fps_median"]
    entry["qvr_over_sw"] = q["fps_median"] / s["fps_median"]
    entry["p99_qvr_over_best"] = q["mtp_p99_median"] / b["mtp_p99_median"]
    # The claim (docs/BENCHMARKS.md): qvr within 5% of the best fixed e1 in hindsight, in FPS
    # and in MTP p99. qvr against sw is reported beside it, not part of it: they tie.
    entry["holds"] = entry["qvr_over_best"] >= 0.95 and entry["p99_qvr_over_best"] <= 1.05
    rows.append(entry)

json.dump(rows, open(os.path.join(out, "matrix.json"), "w"), indent=2)


def span(v):
    return f"{statistics.median(v):.1f} ({min(v):.1f}–{max(v):.1f})"


def short(name):
    for prefix, to in (("builtin_", ""), ("openarena_", ""), (".down", ""), ("-short", ""),
                       ("-driving-2016", "")):
        name = name.replace(prefix, to)
    return name


lines = ["| condition | best fixed | qvr FPS | best-fixed FPS | qvr/ffr | qvr/best | qvr/sw | "
         "MTP p99 qvr / best (ms) | holds |",
         "|---|---|---|---|---|---|---|---|---|"]
for e in rows:
    b = e["best_fixed"]
    lines.append(
        f"| {short(e['condition'])} | {b.split(':')[1]}° | {span(e['qvr']['fps'])} | "
        f"{span(e[b]['fps'])} | "
        f"{e['qvr_over_ffr']:.2f} | {e['qvr_over_best']:.2f} | {e['qvr_over_sw']:.2f} | "
        f"{e['qvr']['mtp_p99_median']:.0f} / {e[b]['mtp_p99_median']:.0f} | "
        f"{'yes' if e['holds'] else 'no'} |")
lines.append("")
lines.append("Fixed sweep (run 1, FPS): " + "; ".join(
    short(e["condition"]) + ": " + ", ".join(f"{d.split(':')[1]}°={v:.1f}" for d, v in
                                     sorted(e["sweep_fps"].items(), key=lambda kv: float(kv[0].split(':')[1])))
    for e in rows))
open(os.path.join(out, "matrix.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
