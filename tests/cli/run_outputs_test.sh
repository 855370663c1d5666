#!/usr/bin/env bash
# What a short `qvr run` leaves in its folder: the display video as H.264 in MP4 with every
# displayed frame (read back through libavformat into summary.json), and a report with tables,
# figures and a <video> element, no raw JSON. Usage: run_outputs_test.sh QVR
set -uo pipefail
QVR=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A calibration file, so the run does not measure this machine first.
printf '[runtime]\npipeline = "runtime"\nfovea_base_ms = 1\n' >"$tmp/rt.toml"
if ! timeout 300 "$QVR" run --profile small --frames 12 --designs local,qvr --hardware "$tmp/rt.toml" \
    --out "$tmp/run" >"$tmp/out.txt" 2>"$tmp/err.txt"; then
    echo "FAIL: qvr run exited non-zero: $(head -c 600 "$tmp/err.txt")"
    exit 1
fi
if grep -q "fps so far" "$tmp/err.txt"; then
    echo "FAIL: progress printed although stderr is not a terminal"
    exit 1
fi
python3 - "$tmp/run" <<'PY'
import json, os, sys
out = sys.argv[1]
d = json.load(open(os.path.join(out, "summary.json")))
v = d["video"]
assert v["path"] == "qvr_display.mp4" and os.path.getsize(os.path.join(out, v["path"])) > 1000, v
assert "mp4" in v["container"].split(","), v
assert v["codec"] == "h264", v
assert v["frames"] == d["designs"]["qvr"]["frames_displayed"] == 12, v
assert v["width_px"] % 2 == 0 and v["height_px"] % 2 == 0, v
html = open(os.path.join(out, "report.html")).read()
assert "<pre>" not in html and '{"' not in html, "raw JSON in report.html"
assert "<source src='qvr_display.mp4' type='video/mp4'>" in html, "no video element"
assert "<img src='qvr_display_still.png'" in html, "no still"
for key in ["fps_mean", "mtp_ms_mean", "frames_displayed"]:
    assert key in d["designs"]["local"], key
print("PASS: qvr run writes qvr_display.mp4 (%s, %d frames) and a report without JSON dumps"
      % (v["codec"], v["frames"]))
PY
