#!/usr/bin/env bash
# Validates `qvr capacity` against `qvr run --headsets N` for N = 1…MAX on this machine: runs the
# qvr design with N headsets (the same motion and gaze for all, so their FPS differ only by the
# server's sharing), predicts the same counts with the run's calibration and the N = 1 run's
# workload, and prints per N the measured mean FPS per headset beside the predicted one, the
# error, and the headsets per server each says at the target FPS.
#
# Two cores cannot show a real deployment: the N headsets share core 0 (each limited to
# --headset-share of it, so N × share ≤ 1 keeps them from taking each other's time; beyond that
# the model charges max(1/share, N)), the server renders on one core with llvmpipe rather than a
# GPU, and the link is loopback through the emulator. What it does show is the server's one
# render thread divided among N sessions, which is what the capacity model predicts.
#
# Usage: scripts/validate_capacity.sh QVR OUT_DIR [MAX_HEADSETS=4] [SHARE=0.25] [FRAMES=90]
#        [TARGET_FPS=5] [extra qvr run options, e.g. --profile small --hardware FILE]
set -euo pipefail
qvr=${1:?usage: validate_capacity.sh QVR OUT_DIR [MAX] [SHARE] [FRAMES] [TARGET] [run options]}
out=${2:?usage: validate_capacity.sh QVR OUT_DIR [MAX] [SHARE] [FRAMES] [TARGET] [run options]}
max=${3:-4}
share=${4:-0.25}
frames=${5:-90}
target=${6:-5}
shift $(($# < 6 ? $# : 6))
mkdir -p "$out"
for n in $(seq 1 "$max"); do
    nice -n 5 "$qvr" run --headsets "$n" --identical-workloads --designs qvr --frames "$frames" \
        --headset-share "$share" --no-video --quality-every 0 --quiet --out "$out/h$n" "$@" \
        >"$out/h$n.log" 2>&1 || { echo "validate_capacity: run N=$n failed (see $out/h$n.log)" >&2; exit 1; }
done
cal=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['calibration']['path'])" \
    "$out/h1/summary.json")
net=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['net'])" "$out/h1/summary.json")
nice -n 5 "$qvr" capacity --hardware "$cal" --trace "$out/h1/workload.jsonl" --net "$net" \
    --target-fps "$target" --headset-share "$share" --headsets-share-one-core \
    --max-headsets "$max" --every-count --frames "$frames" --json "$out/capacity.json" \
    >"$out/capacity.log"
python3 - "$out" "$max" "$target" <<'EOF'
import json, sys
out, n_max, target = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
pred = {p["headsets"]: p for p in json.load(open(f"{out}/capacity.json"))["points"]}
rows, measured_cap, predicted_cap, worst = [], 0, 0, 0.0
for n in range(1, n_max + 1):
    s = json.load(open(f"{out}/h{n}/summary.json"))
    if "headsets" not in s:  # one headset's summary keeps its keys: the qvr design's
        q = s["designs"]["qvr"]
        s["headsets"] = [q]
        s["server_ms_per_headset_frame"] = q.get("server_busy_ms_mean")
    fps = [h["fps_mean"] for h in s["headsets"] if "fps_mean" in h]
    m = sum(fps) / len(fps) if fps else 0.0
    p = pred[n]["fps_mean"]
    err = 100.0 * (p - m) / m if m > 0 else float("nan")
    worst = max(worst, abs(err))
    if min(fps, default=0.0) >= target and measured_cap == n - 1:
        measured_cap = n
    if p >= target and predicted_cap == n - 1:
        predicted_cap = n
    rows.append((n, m, min(fps, default=0.0), p, err, s.get("jain_fairness_fps", 1.0),
                 s.get("server_ms_per_headset_frame"), pred[n]["server_ms_per_headset_frame"]))
print("N  measured FPS/headset (min)  predicted  error   Jain   server ms/headset-frame meas/pred")
for n, m, lo, p, err, jain, sm, sp in rows:
    sm_text = f"{sm:.1f}" if sm is not None else "-"
    print(f"{n}  {m:8.2f} ({lo:6.2f})          {p:8.2f}  {err:+6.1f}%  {jain:.3f}  {sm_text} / {sp:.1f}")
print(f"headsets per server at {target:g} FPS: measured {measured_cap}, predicted {predicted_cap}")
print(f"largest FPS error {worst:.1f}% (criterion: within 15%)")
json.dump({"rows": [dict(zip(["headsets", "measured_fps", "measured_fps_min", "predicted_fps",
                              "error_pct", "jain_fairness_fps", "server_ms_measured",
                              "server_ms_predicted"], r)) for r in rows],
           "target_fps": target, "measured_headsets": measured_cap,
           "predicted_headsets": predicted_cap, "max_error_pct": worst},
          open(f"{out}/validation.json", "w"), indent=2)
EOF
