#!/usr/bin/env python3
"""What e1 costs each side, from one `qvr run --designs fixed:2,fixed:5,...` folder: per fixed
design the medians of the server's per-frame render / encode / send / service time
(server_frames.csv, sessions in design order), the headset's T_remote, busy time and fovea
render, the periphery bytes and the displayed FPS. Prints a Markdown table.

    python3 scripts/e1_curves.py RUN_DIR"""
import csv
import json
import os
import statistics as st
import sys

run = sys.argv[1]
summary = json.load(open(os.path.join(run, "summary.json")))
order = [d.strip() for d in summary["command"].split("--designs ")[1].split()[0].split(",")]
sessions = []
by_client = {}
with open(os.path.join(run, "server_frames.csv")) as f:
    for r in csv.DictReader(f):
        if r["client"] not in by_client:
            by_client[r["client"]] = []
            sessions.append(r["client"])
        by_client[r["client"]].append(r)
served = [d for d in order if d != "local"]
print("| design | e1 ° | server render ms | encode ms | send ms | server service ms | "
      "T_remote ms | headset busy ms | fovea render ms | periphery KB/frame | FPS |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for design, client in zip(served, sessions):
    rows = by_client[client][3:]  # past the first key frames
    med = lambda key: st.median(sum(float(r[f"{key}{i}"]) for i in range(4)) for r in rows)
    service = st.median((int(r["done_ns"]) - int(r["start_ns"])) / 1e6 for r in rows)
    frames = list(csv.DictReader(open(os.path.join(run, f"frames_{design}.csv"))))[3:]
    fm = lambda key: st.median(float(r[key]) for r in frames if float(r[key]) > 0)
    s = summary["designs"][design]
    print(f"| {design} | {float(rows[0]['e1_deg']):.0f} | {med('render_ms'):.1f} | "
          f"{med('encode_ms'):.1f} | {med('send_ms'):.2f} | {service:.1f} | {fm('t_remote_ms'):.1f} | "
          f"{fm('headset_busy_ms'):.1f} | {fm('t_local_ms'):.1f} | {med('bytes') / 1e3:.1f} | "
          f"{s['fps_mean']:.1f} |")
