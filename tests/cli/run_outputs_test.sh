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
if ! timeout 300 "$QVR" run --profile small --frames 12 --designs local,fixed:10,qvr --hardware "$tmp/rt.toml" \
    --quality-every 6 --out "$tmp/run" >"$tmp/out.txt" 2>"$tmp/err.txt"; then
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
# The video has every frame; the statistics leave out each design's start-up frames.
q = d["designs"]["qvr"]
assert v["frames"] == 12 and q["frames_displayed"] == 12 - q["warmup_frames"], (v, q)
assert q["warmup_frames"] == 10 and q["startup_mtp_ms_max"] > 0, q
assert v["width_px"] % 2 == 0 and v["height_px"] % 2 == 0, v
html = open(os.path.join(out, "report.html")).read()
assert "<pre>" not in html and '{"' not in html, "raw JSON in report.html"
assert "<source src='qvr_display.mp4' type='video/mp4'>" in html, "no video element"
assert "<img src='qvr_display_still.png'" in html, "no still"
for key in ["fps_mean", "mtp_ms_mean", "frames_displayed"]:
    assert key in d["designs"]["local"], key
# The transport's and the handshake's counters, in summary.json and in the report.
for key in ["nacks_sent", "media_forged", "media_replayed", "fec_recoveries", "streams_lost"]:
    assert key in d["designs"]["qvr"], key
for key in ["handshake_timeouts", "pending_evicted", "protocol_errors", "bytes_retransmitted"]:
    assert key in d["server"], key
assert "Transport and security counters" in html and "handshake timeouts" in html
# trace.json: Chrome trace events; every frame's stages in order on one (the headset's) clock.
t = json.load(open(os.path.join(out, "trace.json")))
assert d["trace"]["events"] == len(t["traceEvents"]), (d["trace"], len(t["traceEvents"]))
assert d["trace"]["server_frames"] > 0, d["trace"]
assert abs(d["trace"]["server_offset_ms"]) <= d["trace"]["server_offset_bound_ms"] + 1.0, d["trace"]
stages = {}  # (design pid, frame) -> stage -> [start, end] in µs
flows = {"s": 0, "f": 0}
for e in t["traceEvents"]:
    if e["ph"] in flows:
        flows[e["ph"]] += 1
    if e["ph"] != "X":
        continue
    assert e["dur"] >= 0 and e["ts"] >= -1e3, e
    design = (e["pid"] - 1) // 2
    side = "server" if e["pid"] % 2 == 0 else "headset"
    key = (design, e["args"]["frame"])
    stage = side + ":" + e["name"].split(" ")[0]
    a = stages.setdefault(key, {}).setdefault(stage, [e["ts"], e["ts"] + e["dur"]])
    a[0] = min(a[0], e["ts"]); a[1] = max(a[1], e["ts"] + e["dur"])
assert len({k[0] for k in stages}) == 3, "every design on the timeline"
assert flows["s"] == flows["f"] == 36, flows
order = ["headset:decide", "headset:request", "server:queued", "server:render", "server:encode",
         "server:send", "headset:receive", "headset:decode"]
checked = 0
for key, s in stages.items():
    assert "headset:decide" in s and "headset:scan-out" in s, (key, sorted(s))
    assert s["headset:decide"][0] <= s["headset:render"][0], (key, s)
    assert s["headset:UCA"][1] <= s["headset:scan-out"][0] + 1e-3, (key, s)
    present = [st for st in order if st in s]
    for a, b in zip(present, present[1:]):
        assert s[a][0] <= s[b][0] + 1e-3, ("frame", key, a, "after", b, s)
    if "server:send" in s and "headset:receive" in s:
        assert s["server:send"][1] <= s["headset:receive"][1] + 1e-3, (key, s)
        checked += 1
assert checked >= 10, checked
print("PASS: trace.json holds %d frames, stages in order; server offset %+.3f ms +- %.3f ms"
      % (len(stages), d["trace"]["server_offset_ms"], d["trace"]["server_offset_bound_ms"]))
# Image quality: every design sampled (frames 6 and 12), the bands its plan has, in the report.
q = d["quality"]
for name in ["local", "fixed:10", "qvr"]:
    assert q[name]["frames_sampled"] == 2, q
    assert 0.0 < q[name]["all"]["ssim"] <= 1.0 and q[name]["all"]["psnr_db"] > 10, q[name]
    assert q[name]["psnr_db_by_eccentricity_deg"], q[name]
    assert "<td class='l'>%s</td><td>2</td>" % name in html, "quality table row " + name
assert "middle" not in q["local"], "local renders everything as its fovea"
# The fovea band is e < e1 less the blend band (two middle-layer texels), so a design whose
# fovea LIWC shrank below that width on the sampled frames has none: compare on fixed:10.
f = q["fixed:10"]
assert f["fovea"]["psnr_db"] > f["outer"]["psnr_db"] + 3, f
assert "all" in q["qvr"] and ("fovea" in q["qvr"] or "middle" in q["qvr"]), q["qvr"]
assert "temporal flicker" in html
print("PASS: quality by band for every design (fixed:10 fovea %.1f dB, outer %.1f dB)"
      % (f["fovea"]["psnr_db"], f["outer"]["psnr_db"]))
print("PASS: qvr run writes qvr_display.mp4 (%s, %d frames) and a report without JSON dumps"
      % (v["codec"], v["frames"]))
PY
status=$?
[ "$status" -eq 0 ] || exit "$status"
# A design that asks for the server's layers and never shows one (a link so slow the first key
# frame cannot cross it in the run) is a failed run: everything written, the design flagged, a
# message, exit 1 — never stale frames reported as numbers with exit 0.
timeout 120 "$QVR" run --profile small --frames 14 --designs remote --net rate:0.01 \
    --hardware "$tmp/rt.toml" --no-video --out "$tmp/never" >"$tmp/never.txt" 2>"$tmp/never_err.txt"
rc=$?
if [ "$rc" -ne 1 ]; then
    echo "FAIL: a run that never showed the server's layers exited $rc, not 1"
    exit 1
fi
grep -q "remote never showed a layer from the server" "$tmp/never_err.txt" || {
    echo "FAIL: no message: $(head -c 400 "$tmp/never_err.txt")"
    exit 1
}
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['designs']['remote']['startup_unfinished'] is True" \
    "$tmp/never/summary.json" || { echo "FAIL: startup_unfinished not set"; exit 1; }
echo "PASS: a run whose server never reached the screen exits 1 and says so"
