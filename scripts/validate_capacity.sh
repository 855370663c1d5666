#!/usr/bin/env bash
# Validates `qvr capacity` against `qvr run --headsets N` for N = 1…MAX on this machine: runs the
# qvr design with N headsets (the same motion and gaze for all, so their FPS differ only by the
# server's sharing) REPEATS times, each round in a rotated order of N (the host's speed drifts by
# 20–40% over minutes: one run per N is not a measurement), predicts the same counts with the
# first round's calibration and N = 1 workload, and prints per N the median over the rounds of the
# mean FPS per headset, each round's, the predicted one, the error, the run's own prediction (qvr
# run predicts N headsets with the same factors) and the headsets per server each says at the
# target FPS.
#
# Two cores cannot show a real deployment: the N headsets share core 0 (each limited to
# --headset-share of it, each in its own CPU share group, so N × share ≤ 1 keeps them from taking
# each other's time; beyond that the model charges max(1/share, N)), the server renders on one
# core with llvmpipe rather than a GPU, and the link is loopback through the emulator. What it
# does show is the server's one render thread divided among N sessions, which is what the
# capacity model predicts.
#
# Usage: scripts/validate_capacity.sh QVR OUT_DIR [MAX_HEADSETS=4] [SHARE=0.25] [FRAMES=90]
#        [TARGET_FPS=5] [REPEATS=3] [extra qvr run options, e.g. --profile small]
# DESIGN=fixed:5 (environment; default qvr) validates another design: a fixed e1 takes LIWC's
# choices out and leaves the server's and the headsets' costs. The workload is a qvr design's:
# round 1's N = 1 run, or for another design one more qvr run (OUT/wl). REUSE=1 keeps the runs an
# earlier call left in OUT_DIR and only predicts again.
#
# Two predictions per N: at the calibration's speed (the machine as it was calibrated, a cached
# calibration maybe hours before), and at the speed the runs' own probes measured (qvr capacity
# --headset-speed/--server-speed: the median over every run of summary.json
# calibration.speed_reference.run_over_reference, the fixed reference frames timed before and
# after each run). The second is the model's error; the gap between the two is the machine's
# drift. One speed for all the runs, not one per N: a probe times 0.6 s on core 0, and this
# host's cores each slow to ~0.55x in stretches of 3-9 s, independently (docs/MODEL.md §11), so a
# run's two probes are a poor estimate of its own speed and the median of all of them the best.
set -euo pipefail
usage="usage: validate_capacity.sh QVR OUT_DIR [MAX] [SHARE] [FRAMES] [TARGET] [REPEATS] [options]"
qvr=${1:?$usage}
out=${2:?$usage}
max=${3:-4}
share=${4:-0.25}
frames=${5:-90}
target=${6:-5}
repeats=${7:-3}
shift $(($# < 7 ? $# : 7))
design=${DESIGN:-qvr}
mkdir -p "$out"
for r in $(seq 1 "$repeats"); do
    mkdir -p "$out/r$r"
    for k in $(seq 0 $((max - 1))); do
        n=$(((k + r - 1) % max + 1))
        dir="$out/r$r/h$n"
        [ "${REUSE:-0}" = 1 ] && [ -s "$dir/summary.json" ] && continue
        nice -n 5 "$qvr" run --headsets "$n" --identical-workloads --designs "$design" \
            --frames "$frames" --headset-share "$share" --no-video --quality-every 0 --quiet \
            --out "$dir" "$@" >"$dir.log" 2>&1 ||
            { echo "validate_capacity: run N=$n failed (see $dir.log)" >&2; exit 1; }
    done
done
first="$out/r1/h1/summary.json"
workload="$out/r1/h1/workload.jsonl"
if [ "$design" != qvr ]; then  # only the qvr design records its workload
    workload="$out/wl/workload.jsonl"
    nice -n 5 "$qvr" run --designs qvr --frames "$frames" --headset-share "$share" --no-video \
        --quality-every 0 --quiet --out "$out/wl" "$@" >"$out/wl.log" 2>&1 ||
        { echo "validate_capacity: the workload run failed (see $out/wl.log)" >&2; exit 1; }
fi
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))$1)" "$first"; }
cal=$(field "['calibration']['path']")
net=$(field "['net']")
scene=$(field "['scene']")
lod=$(python3 -c "import json,re,sys; m=re.search(r'--lod-px (\S+)', json.load(open(sys.argv[1]))['command']); print(m.group(1) if m else 1)" "$first")
capacity() {  # capacity JSON [options]: qvr capacity on the workload, every count
    local json=$1
    shift
    nice -n 5 "$qvr" capacity --hardware "$cal" --trace "$workload" --net "$net" \
        --design "$design" --scene "$scene" --lod-px "$lod" --target-fps "$target" \
        --headset-share "$share" --headsets-share-one-core --every-count --frames "$frames" \
        --json "$json" "$@" >"${json%.json}.log" ||
        { echo "validate_capacity: qvr capacity failed (see ${json%.json}.log)" >&2; exit 1; }
}
capacity "$out/capacity.json" --max-headsets "$max"
# The median factors over every run with probes: two words (none: the calibration has no speed
# reference or the probes failed, and there is no speed to predict at).
speeds=$(python3 - "$out" "$max" "$repeats" <<'EOF'
import json, statistics, sys
out, n_max, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
f = [json.load(open(f"{out}/r{r}/h{n}/summary.json"))["calibration"]["speed_reference"]
     .get("run_over_reference") for r in range(1, repeats + 1) for n in range(1, n_max + 1)]
f = [x for x in f if x]
if f:
    print(*(statistics.median(x[side] for x in f) for side in ("headset", "server")))
EOF
)
[ -n "$speeds" ] ||
    { echo "validate_capacity: no run has speed probes (calibration.speed_reference)" >&2; exit 1; }
read -r h_speed s_speed <<<"$speeds"
capacity "$out/capacity_at_probe_speed.json" --max-headsets "$max" --headset-speed "$h_speed" \
    --server-speed "$s_speed"
python3 - "$out" "$max" "$target" "$repeats" "$design" <<'EOF'
import json, statistics, sys
out, n_max, target, repeats = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
design = sys.argv[5]
pred = {p["headsets"]: p for p in json.load(open(f"{out}/capacity.json"))["points"]}
c = json.load(open(f"{out}/capacity_at_probe_speed.json"))
at_speed, speed = {p["headsets"]: p for p in c["points"]}, c["speed"]


def reading(path):
    s = json.load(open(path))
    if "headsets" not in s:  # one headset's summary keeps its keys: the design's
        q = s["designs"][design]
        s["headsets"] = [q]
        s["server_ms_per_headset_frame"] = q.get("server_busy_ms_mean")
    fps = [h["fps_mean"] for h in s["headsets"] if "fps_mean" in h]
    return {"fps": sum(fps) / len(fps) if fps else 0.0, "fps_min": min(fps, default=0.0),
            "jain": s.get("jain_fairness_fps", 1.0),
            "server_ms": s.get("server_ms_per_headset_frame") or float("nan"),
            "own": s["designs"][design].get("predicted", {}).get("fps_mean", float("nan"))}


def error_pct(p, m):
    return 100.0 * (p - m) / m if m > 0 else float("nan")


def count_at_target(fps_by_n):  # counts from 1 in order, as qvr capacity does
    count = 0
    for n in range(1, n_max + 1):
        if fps_by_n[n] < target:
            break
        count = n
    return count


rows = []
for n in range(1, n_max + 1):
    takes = [reading(f"{out}/r{r}/h{n}/summary.json") for r in range(1, repeats + 1)]
    med = {k: statistics.median(t[k] for t in takes) for k in takes[0]}
    m, p, q = med["fps"], pred[n]["fps_mean"], at_speed[n]["fps_mean"]
    rows.append({"headsets": n, "measured_fps": m, "measured_fps_takes": [t["fps"] for t in takes],
                 "measured_fps_min": med["fps_min"], "predicted_fps": p,
                 "error_pct": error_pct(p, m),
                 "predicted_fps_at_probe_speed": q, "error_pct_at_probe_speed": error_pct(q, m),
                 "jain_fairness_fps": med["jain"], "server_ms_measured": med["server_ms"],
                 "server_ms_predicted": pred[n]["server_ms_per_headset_frame"],
                 "server_ms_predicted_at_probe_speed": at_speed[n]["server_ms_per_headset_frame"],
                 "run_predicted_fps": med["own"]})
measured_cap = count_at_target({r["headsets"]: r["measured_fps_min"] for r in rows})
predicted_cap = count_at_target({r["headsets"]: r["predicted_fps"] for r in rows})
predicted_cap_at_speed = count_at_target(
    {r["headsets"]: r["predicted_fps_at_probe_speed"] for r in rows})
worst = max(abs(r["error_pct"]) for r in rows)
worst_at_speed = max(abs(r["error_pct_at_probe_speed"]) for r in rows)
print(f"the runs' probes: x{speed['headset']:.2f} the calibration's headset times, "
      f"x{speed['server']:.2f} its server's (medians over {n_max * repeats} runs)")
print("N  measured FPS/headset: median [each round]  | predicted, error: at the calibration's "
      "speed | at the probes' | Jain | server ms/headset-frame measured / predicted at the "
      "probes' | run's own prediction")
for r in rows:
    m, own = r["measured_fps"], r["run_predicted_fps"]
    takes = ", ".join(f"{x:.2f}" for x in r["measured_fps_takes"])
    own_text = f"{own:.2f} ({error_pct(own, m):+.1f}%)" if own == own and m > 0 else "-"
    print(f"{r['headsets']}  {m:6.2f} [{takes}]  | {r['predicted_fps']:6.2f} "
          f"{r['error_pct']:+6.1f}% | {r['predicted_fps_at_probe_speed']:6.2f} "
          f"{r['error_pct_at_probe_speed']:+6.1f}% | "
          f"{r['jain_fairness_fps']:.3f} | {r['server_ms_measured']:.1f} / "
          f"{r['server_ms_predicted_at_probe_speed']:.1f} | {own_text}")
print(f"headsets per server at {target:g} FPS: measured {measured_cap}, predicted "
      f"{predicted_cap_at_speed} at the probes' speed ({predicted_cap} at the calibration's)")
print(f"largest FPS error {worst_at_speed:.1f}% at the probes' speed, {worst:.1f}% at the "
      "calibration's (criterion: within 15%)")
json.dump({"rows": rows, "repeats": repeats, "target_fps": target, "probe_speed": speed,
           "measured_headsets": measured_cap, "predicted_headsets": predicted_cap,
           "predicted_headsets_at_probe_speed": predicted_cap_at_speed,
           "max_error_pct": worst, "max_error_pct_at_probe_speed": worst_at_speed},
          open(f"{out}/validation.json", "w"), indent=2)
EOF
