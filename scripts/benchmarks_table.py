#!/usr/bin/env python3
"""Writes the headline table that opens docs/BENCHMARKS.md from a `qvr run` and a `qvr eval`.

Two ways to call it:

  # from outputs that exist (summary.json of `qvr run --out RUN`, summary.json and report.html
  # of `qvr eval --out EVAL`)
  python3 scripts/benchmarks_table.py --run-out RUN --eval-out EVAL --write docs/BENCHMARKS.md

  # measure first: runs `qvr run --out OUT/run` and `qvr eval --out OUT/eval`, then writes
  python3 scripts/benchmarks_table.py --measure OUT --write docs/BENCHMARKS.md \
      [--qvr build/release/apps/qvr/qvr] [--run-args "--frames 20 --designs ffr,qvr"]

The table replaces what lies between the two marker comments of the file (MARK_BEGIN, MARK_END);
without --write it is printed. Bad input (a missing file, a file without the markers) gives a
message and exit 2.
"""

import argparse
import html
import json
import re
import shlex
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

MARK_BEGIN = "<!-- benchmarks_table:begin (scripts/benchmarks_table.py writes this block) -->"
MARK_END = "<!-- benchmarks_table:end -->"
DEFAULT_QVR = "build/release/apps/qvr/qvr"


def fail(message):
    print(f"benchmarks_table: {message}", file=sys.stderr)
    sys.exit(2)


def read_json(path):
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        fail(f"cannot read {path}: {e}")


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return "unknown CPU (lscpu failed)"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown CPU"


def machine_text(run):
    """`lscpu`'s model name, with the run's own description where it names another machine."""
    model, machine = cpu_model(), run.get("machine", "")
    if not machine or model in machine:
        return machine or model
    return f"{model} (`lscpu` here; the run's summary.json says {machine})"


def design_order(name):
    """local, remote, ffr, fixed:E by E, sw, qvr; anything else after them by name."""
    rank = {"local": 0, "remote": 1, "ffr": 2, "sw": 4, "qvr": 5}
    if name.startswith("fixed:"):
        try:
            return (3, float(name.split(":", 1)[1]), name)
        except ValueError:
            return (3, 0.0, name)
    return (rank.get(name, 6), 0.0, name)


def num(v, fmt):
    return format(v, fmt) if isinstance(v, (int, float)) else "—"


def with_error(predicted, error_pct, fmt):
    if not isinstance(predicted, (int, float)):
        return "—"
    if not isinstance(error_pct, (int, float)):
        return format(predicted, fmt)
    return f"{format(predicted, fmt)} ({error_pct:+.1f}%)"


def run_table(summary):
    """One row per design: measured, and the calibrated model's prediction with its error."""
    designs = summary.get("designs", {})
    if not designs:
        fail("the qvr run summary.json has no designs")
    rows = [
        "| design | FPS | MTP p99 ms | bytes/frame | e1 ° "
        "| predicted FPS (error) | predicted MTP p99 ms (error) | predicted bytes (error) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in sorted(designs, key=design_order):
        d = designs[name]
        p = d.get("predicted", {})
        e = d.get("prediction_error_pct", {})
        rows.append(
            f"| {name} | {num(d.get('fps_mean'), '.1f')} | {num(d.get('mtp_ms_p99'), '.1f')} "
            f"| {num(d.get('bytes_per_frame_mean'), ',.0f') if name != 'local' else '—'} "
            f"| {num(d.get('e1_deg_mean'), '.1f')} "
            f"| {with_error(p.get('fps_mean'), e.get('fps_mean'), '.1f')} "
            f"| {with_error(p.get('mtp_ms_p99'), e.get('mtp_ms_p99'), '.1f')} "
            f"| {with_error(p.get('bytes_per_frame_mean'), e.get('bytes_per_frame_mean'), ',.0f') if name != 'local' else '—'} |"
        )
    return rows


def eval_headlines(eval_dir):
    """(metric, paper, faithful, fitted) of `qvr eval`: summary.json's "headlines" if it has them,
    else the "Headline figures" table of report.html (fitted is "" where the report has no
    fitted column; a column after fitted, the mechanism behind a fitted figure, is left out)."""
    summary = read_json(Path(eval_dir) / "summary.json")
    if isinstance(summary.get("headlines"), list):
        return [
            (h["metric"], f"{h['paper']:.2f}{h.get('unit', '')}",
             f"{h['ours']:.2f}{h.get('unit', '')}",
             f"{h['fitted']:.2f}{h.get('unit', '')}" if "fitted" in h else "")
            for h in summary["headlines"]
        ]
    report = Path(eval_dir) / "report.html"
    try:
        text = report.read_text()
    except OSError as e:
        fail(f"cannot read {report}: {e}")
    m = re.search(r"Headline figures.*?<table>(.*?)</table>", text, re.S)
    if not m:
        fail(f"{report} has no 'Headline figures' table")
    out = []
    for row in re.findall(r"<tr>(.*?)</tr>", m.group(1), re.S):
        cells = [html.unescape(re.sub(r"<[^>]+>", "", c)).strip()
                 for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
        if len(cells) == 3:
            out.append((*cells, ""))
        elif len(cells) >= 4:  # paper, faithful, fitted, then the mechanism of a fitted figure
            out.append(tuple(cells[:4]))
    if not out:
        fail(f"{report}'s headline table has no rows")
    return out


def eval_command(eval_dir):
    try:
        text = (Path(eval_dir) / "report.html").read_text()
    except OSError:
        return "qvr eval"
    m = re.search(r"Command: <code>(.*?)</code>", text, re.S)
    return html.unescape(m.group(1)) if m else "qvr eval"


def host_line(run):
    """Whether the host held its calibration's speed over the run (docs/MODEL.md §11)."""
    ref = run.get("calibration", {}).get("speed_reference", {})
    spread = ref.get("run_spread_pct") or {}
    if not isinstance(ref.get("unsteady"), bool) or not spread:
        return ""
    moved = ", ".join(f"{side} {num(v, '.0f')}%" for side, v in spread.items())
    word = "unsteady" if ref["unsteady"] else "steady"
    return f"Host {word} over the run (speed probes moved {moved})."


def block(run_dir, eval_dir, note):
    run = read_json(Path(run_dir) / "summary.json")
    date = run.get("date") or datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [MARK_BEGIN, ""]
    if note:
        lines += [f"**{note}**", ""]
    lines += [
        f"Measured {date} on {machine_text(run)}; "
        f"scene {run.get('scene', '?')}, link {run.get('net', '?')}, "
        f"{run.get('frames_per_design', '?')} frames a design.",
        "",
        f"`{run.get('command', 'qvr run')}` — measured, and the calibrated model's prediction "
        "(signed error, percent of the measurement):",
        "",
    ]
    lines += run_table(run)
    host = host_line(run)
    if host:
        lines += ["", host]
    ratios = run.get("ratios", {})
    if "qvr_fps_over_local" in ratios or "qvr_bytes_saved_vs_remote" in ratios:
        parts = []
        if "qvr_fps_over_local" in ratios:
            parts.append(f"qvr FPS over local {ratios['qvr_fps_over_local']:.1f}×")
        if "qvr_bytes_saved_vs_remote" in ratios:
            parts.append(f"qvr bytes saved against remote "
                         f"{100 * ratios['qvr_bytes_saved_vs_remote']:.1f}%")
        lines += ["", "; ".join(parts) + "."]
    lines += ["", f"`{eval_command(eval_dir)}` — the simulator on the paper's hardware, "
              "the paper's headline figures beside the faithful model's and the fitted variant's "
              "(docs/EVAL.md):", "",
              "| headline | paper | faithful | fitted |", "|---|---|---|---|"]
    lines += [f"| {m} | {p} | {o} | {f} |" for m, p, o, f in eval_headlines(eval_dir)]
    lines += ["", MARK_END]
    return "\n".join(lines)


def write_into(path, text):
    try:
        doc = Path(path).read_text()
    except OSError as e:
        fail(f"cannot read {path}: {e}")
    begin, end = doc.find(MARK_BEGIN), doc.find(MARK_END)
    if begin < 0 or end < begin:
        fail(f"{path} lacks the markers '{MARK_BEGIN}' … '{MARK_END}'")
    Path(path).write_text(doc[:begin] + text + doc[end + len(MARK_END):])


def measure(qvr, out, run_args, eval_args):
    run_dir, eval_dir = Path(out) / "run", Path(out) / "eval"
    for cmd in ([qvr, "run", "--out", str(run_dir), *shlex.split(run_args)],
                [qvr, "eval", "--out", str(eval_dir), *shlex.split(eval_args)]):
        print("benchmarks_table: running " + shlex.join(cmd), file=sys.stderr)
        rc = subprocess.run(cmd).returncode
        if rc != 0:
            print(f"benchmarks_table: {shlex.join(cmd)} exited {rc}", file=sys.stderr)
            sys.exit(1)
    return run_dir, eval_dir


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run-out", help="folder of an existing `qvr run --out`")
    ap.add_argument("--eval-out", help="folder of an existing `qvr eval --out`")
    ap.add_argument("--measure", metavar="OUT",
                    help="run `qvr run` and `qvr eval` into OUT/run and OUT/eval first")
    ap.add_argument("--qvr", default=DEFAULT_QVR, help="the qvr binary (with --measure)")
    ap.add_argument("--run-args", default="", help="extra `qvr run` options (with --measure)")
    ap.add_argument("--eval-args", default="", help="extra `qvr eval` options (with --measure)")
    ap.add_argument("--note", default="", help="a line printed in bold above the table")
    ap.add_argument("--write", metavar="FILE", help="rewrite the block between the markers")
    a = ap.parse_args()
    if a.measure:
        if a.run_out or a.eval_out:
            fail("--measure writes its own outputs: give it without --run-out/--eval-out")
        run_dir, eval_dir = measure(a.qvr, a.measure, a.run_args, a.eval_args)
    elif a.run_out and a.eval_out:
        run_dir, eval_dir = a.run_out, a.eval_out
    else:
        fail("give --run-out and --eval-out, or --measure OUT")
    text = block(run_dir, eval_dir, a.note)
    if a.write:
        write_into(a.write, text)
    else:
        print(text)


if __name__ == "__main__":
    main()
