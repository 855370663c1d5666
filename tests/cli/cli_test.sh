#!/usr/bin/env bash
# The qvr command line (issue 2's machine-readable output and bad input): `qvr plan --json` and
# `qvr control --json` carry the names other tools read, and every bad input exits non-zero with
# a message on stderr instead of crashing. Usage: cli_test.sh /path/to/qvr
set -u

QVR=${1:?usage: cli_test.sh /path/to/qvr}
passed=0
failed=0
tmp=$(mktemp -d "${TMPDIR:-/tmp}/qvr_cli_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

pass() {
    passed=$((passed + 1))
    echo "ok   $1"
}
fail() {
    failed=$((failed + 1))
    echo "FAIL $1"
    [ $# -gt 1 ] && echo "     $2"
}

# run_ok NAME ARGS...: must exit 0; stdout lands in $tmp/out.json.
run_ok() {
    local name=$1
    shift
    "$QVR" "$@" >"$tmp/out.json" 2>"$tmp/err.txt"
    local rc=$?
    if [ $rc -eq 0 ]; then
        return 0
    fi
    fail "$name" "exit $rc: $(head -c 300 "$tmp/err.txt")"
    return 1
}

# check_json NAME PYTHON: runs PYTHON with `d` bound to the parsed $tmp/out.json; an assertion
# error or exception fails the check.
check_json() {
    local name=$1
    local code=$2
    local msg
    if msg=$(python3 -c "
import json, math, sys
d = json.load(open(sys.argv[1]))
$code
" "$tmp/out.json" 2>&1); then
        pass "$name"
    else
        fail "$name" "$(echo "$msg" | tail -n 3)"
    fi
}

# expect_error NAME ARGS...: must exit non-zero, below 128 (no signal), with a message on stderr.
expect_error() {
    local name=$1
    shift
    timeout 120 "$QVR" "$@" >"$tmp/bad_out.txt" 2>"$tmp/bad_err.txt"
    local rc=$?
    if [ $rc -eq 0 ]; then
        fail "$name" "exit 0 for: $*"
    elif [ $rc -ge 124 ]; then
        fail "$name" "exit $rc (crash, signal or timeout) for: $*"
    elif [ ! -s "$tmp/bad_err.txt" ]; then
        fail "$name" "exit $rc but nothing on stderr for: $*"
    else
        pass "$name (exit $rc: $(head -n 1 "$tmp/bad_err.txt" | cut -c1-90))"
    fi
}

if ! command -v python3 >/dev/null; then
    echo "python3 is needed to check JSON output"
    echo "0 passed, 1 failed"
    exit 1
fi

# --- qvr plan --------------------------------------------------------------------------------
if run_ok "plan --e1 15 --json runs" plan --e1 15 --json; then
    check_json "plan --json has e1_deg, e2_deg, s1, s2 and per-layer pixels" '
for k in ("e1_deg", "e2_deg", "s1", "s2"):
    assert isinstance(d[k], (int, float)) and math.isfinite(d[k]), k
for k in ("fovea", "middle", "outer", "full"):
    assert isinstance(d["pixels"][k], int) and d["pixels"][k] >= 0, k
assert d["e1_deg"] == 15, d["e1_deg"]
assert d["e2_deg"] >= d["e1_deg"], d["e2_deg"]
assert 1 <= d["s1"] <= d["s2"], (d["s1"], d["s2"])
assert d["pixels"]["full"] == 1920 * 2160, d["pixels"]["full"]
assert 0 < d["pixels"]["fovea"] < d["pixels"]["full"]
assert d["pixels"]["middle"] + d["pixels"]["outer"] > 0
# The periphery at its scales is far smaller than the full frame it replaces.
assert d["pixels"]["middle"] + d["pixels"]["outer"] < d["pixels"]["full"] / 4
'
fi

if run_ok "plan --profile low --gaze 10,-5 --json runs" plan --e1 8 --gaze 10,-5 --profile low --json; then
    check_json "plan on the low-res profile counts 1280x1600" '
assert d["pixels"]["full"] == 1280 * 1600, d["pixels"]["full"]
assert d["e1_deg"] == 8
'
fi

if run_ok "plan --e1 90 --json runs" plan --e1 90 --json; then
    check_json "plan with a fovea covering the field has no remote layer" '
p = d["pixels"]
assert p["middle"] == 0 and p["outer"] == 0, p
assert p["fovea"] == p["full"], p
'
fi

cat >"$tmp/good.toml" <<'TOML'
name = "tiny"
[display]
width_px = 640
height_px = 480
[fov]
horizontal_deg = 90
vertical_deg = 80
TOML
if run_ok "plan --profile <good toml> runs" plan --e1 10 --profile "$tmp/good.toml" --json; then
    check_json "plan reads the profile file" '
assert d["pixels"]["full"] == 640 * 480, d["pixels"]["full"]
'
fi

# --- qvr control -----------------------------------------------------------------------------
if run_ok "control --policy liwc --frames 300 --json runs" control --policy liwc --frames 300 --json; then
    check_json "control --json has frames and summary with the documented names" '
f = d["frames"]
assert len(f) == 300, len(f)
assert f[0]["e1_deg"] == 5, f[0]["e1_deg"]
for x in f:
    for k in ("e1_deg", "t_local_ms", "t_remote_ms"):
        assert isinstance(x[k], (int, float)) and math.isfinite(x[k]) and x[k] >= 0, (k, x)
s = d["summary"]
assert "frame_ms_mean" in s and "frames_to_balance" in s, s.keys()
mean = sum(max(x["t_local_ms"], x["t_remote_ms"]) for x in f) / len(f)
assert abs(s["frame_ms_mean"] - mean) <= 1e-9 * mean, (s["frame_ms_mean"], mean)
'
    check_json "control summary.frames_to_balance matches the frames and is within 30" '
f = d["frames"]
first = None
for i in range(len(f) - 1, -1, -1):
    l, r = f[i]["t_local_ms"], f[i]["t_remote_ms"]
    if l > 0 and abs(r / l - 1) < 0.15:
        first = i
    else:
        break
assert d["summary"]["frames_to_balance"] == first, (d["summary"]["frames_to_balance"], first)
assert first is not None and first <= 30, first
'
fi

if run_ok "control --policy fixed --frames 20 --json runs" control --policy fixed --frames 20 --json; then
    check_json "control with the fixed policy keeps e1 at 5" '
assert len(d["frames"]) == 20
assert all(x["e1_deg"] == 5 for x in d["frames"])
'
fi

# --- bad input -------------------------------------------------------------------------------
printf 'name = "broken\n[display\nwidth_px = = 3\n' >"$tmp/malformed.toml"
printf '[display]\nwidth_px = 0\n' >"$tmp/zero_width.toml"
# A well-formed trace written by hand from docs/WORKLOAD_FORMAT.md, then broken on line 3.
python3 - "$tmp/good.jsonl" <<'PY'
import json, sys
rings = 60
header = {"format": "qvr-workload", "version": 1, "name": "cli-hand-made", "source": "cli_test.sh",
          "profile": {"name": "default", "width_px": 1920, "height_px": 2160, "fov_h_deg": 100.0,
                      "fov_v_deg": 110.0, "refresh_hz": 90.0},
          "ring_deg": 1.0, "rings": rings, "scales": [1, 2, 4, 8, 16, 32], "batches": 100}
with open(sys.argv[1], "w") as out:
    out.write(json.dumps(header) + "\n")
    for i in range(12):
        frame = {"i": i, "t_ms": i * 1000.0 / 90.0,
                 "head": {"q": [1, 0, 0, 0], "p": [0, 1.7, 0]}, "gaze": [0.5 * i, -0.2 * i],
                 "tri": [4000.0 * (k + 1) for k in range(rings)],
                 "pix": [60000.0 for k in range(rings)],
                 "bpp": [0.6 * s ** 0.7 for s in header["scales"]],
                 "static": {"fg_tri": 1000.0, "fg_frac": 0.2, "bg_bytes": 5e4, "depth_bytes": 2e4}}
        out.write(json.dumps(frame) + "\n")
PY
{ head -n 2 "$tmp/good.jsonl"; echo 'not json at all'; tail -n +4 "$tmp/good.jsonl"; } >"$tmp/malformed.jsonl"
printf '' >"$tmp/empty.jsonl"
head -c 4096 /dev/urandom >"$tmp/random.jsonl" 2>/dev/null || printf '\x00\xff\x01' >"$tmp/random.jsonl"

if run_ok "control --trace <hand-written trace> runs" control --policy liwc --trace "$tmp/good.jsonl" --frames 50 --json; then
    check_json "control runs every frame of the trace and starts at 5" '
assert d["workload"]["name"] == "cli-hand-made", d["workload"]
assert len(d["frames"]) == 12, len(d["frames"])
assert d["frames"][0]["e1_deg"] == 5
'
fi

expect_error "unknown subcommand" frobnicate
expect_error "no subcommand"
expect_error "plan --e1 -3" plan --e1 -3
expect_error "plan --e1 abc" plan --e1 abc
expect_error "plan --gaze foo" plan --gaze foo
expect_error "plan --gaze 90,0 (outside +-80)" plan --gaze 90,0
expect_error "plan --gaze 1,2,3" plan --gaze 1,2,3
expect_error "plan --profile /nonexistent.toml" plan --profile /nonexistent.toml
expect_error "plan --profile <malformed toml>" plan --profile "$tmp/malformed.toml"
expect_error "plan --profile <width 0>" plan --profile "$tmp/zero_width.toml"
expect_error "plan --profile <a directory>" plan --profile "$tmp"
# Every floating-point option refuses NaN and infinities when parsed; an empty profile file is
# not the default profile.
: >"$tmp/empty.toml"
expect_error "plan --profile <empty file>" plan --profile "$tmp/empty.toml"
expect_error "plan --e1 nan" plan --e1 nan
expect_error "plan --gaze nan,0" plan --gaze nan,0
expect_error "control --gpu-mhz nan" control --gpu-mhz nan --frames 5
expect_error "control --throughput-mbps inf" control --throughput-mbps inf --frames 5
expect_error "control --e1 nan" control --policy fixed --e1 nan --frames 5
expect_error "sim --gpu-mhz nan" sim --bench grid --gpu-mhz nan --out "$tmp/x"
expect_error "sim --wait-limit-ms nan" sim --bench grid --pipeline runtime --wait-limit-ms nan --out "$tmp/x"
expect_error "sim --seed -1" sim --bench grid --seed -1 --out "$tmp/x"
expect_error "trace gaze --rate inf" trace gaze --rate inf --out "$tmp/g.csv"
expect_error "trace gaze --pursuit nan" trace gaze --pursuit nan --out "$tmp/g.csv"
expect_error "trace gaze --out into a missing folder" trace gaze --out "$tmp/missing/g.csv"
expect_error "trace motion --smooth-ms nan" trace motion --default --smooth-ms nan --out "$tmp/m.csv"
expect_error "scene count --far-m inf" scene count builtin:room --far-m inf
expect_error "render --ipd-mm nan" render builtin:room --ipd-mm nan --out "$tmp/render"
expect_error "bench uca --yaw nan" bench uca --yaw nan
expect_error "compose --e1 nan" compose --e1 nan --out "$tmp/c.png"
if [ -e "$tmp/x" ] || [ -e "$tmp/g.csv" ] || [ -e "$tmp/render" ] || [ -e "$tmp/c.png" ]; then
    fail "refused options leave no output" "$(ls "$tmp")"
else
    pass "refused options leave no output"
fi
expect_error "control --policy bogus" control --policy bogus
expect_error "control --frames 0" control --frames 0
expect_error "control --frames -5" control --frames -5
expect_error "control --trace /nonexistent" control --trace /nonexistent
expect_error "control --trace <malformed trace>" control --trace "$tmp/malformed.jsonl"
if grep -q "malformed.jsonl:3:" "$tmp/bad_err.txt"; then
    pass "control --trace <malformed trace> names line 3"
else
    fail "control --trace <malformed trace> names line 3" "$(head -c 300 "$tmp/bad_err.txt")"
fi
expect_error "control --trace <empty file>" control --trace "$tmp/empty.jsonl"
expect_error "control --trace <random bytes>" control --trace "$tmp/random.jsonl"
expect_error "control --trace <a directory>" control --trace "$tmp"
expect_error "control --bench nope" control --bench nope --frames 5
expect_error "control --net dialup" control --net dialup --frames 5
expect_error "control --trace and --bench together" control --trace "$tmp/empty.jsonl" --bench synthetic-grid


# The runtime pipeline model (qvr sim --pipeline runtime) on the hand-written trace, and the
# calibration file grammar.
if run_ok "sim --pipeline runtime runs" sim --trace "$tmp/good.jsonl" --pipeline runtime --design qvr --out "$tmp/simrt"; then
    python3 - "$tmp/simrt/summary.json" <<'PY' && pass "sim --pipeline runtime writes its summary" || fail "sim --pipeline runtime writes its summary"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["pipeline"] == "runtime" and d["frames"] == 12, d
assert d["fps_mean"] > 0 and d["mtp_ms_mean"] > 0 and d["bytes_per_frame_mean"] > 0, d
PY
fi
printf '[runtime]\npipeline = "runtime"\nfovea_base_ms = 1\n' >"$tmp/rt.toml"
run_ok "sim --hardware <runtime pipeline file> selects the runtime model" sim --trace "$tmp/good.jsonl" --hardware "$tmp/rt.toml" --design ffr --out "$tmp/simrt2" &&
    grep -q '"pipeline": "runtime"' "$tmp/simrt2/summary.json" && pass "the hardware file chose the runtime model"
printf '[runtime]\npipeline = "fast"\n' >"$tmp/rt_bad.toml"
printf '[runtime]\nfovea_base_ms = -3\n' >"$tmp/rt_neg.toml"
expect_error "sim --hardware <bad runtime.pipeline>" sim --trace "$tmp/good.jsonl" --hardware "$tmp/rt_bad.toml" --out "$tmp/x"
expect_error "sim --hardware <negative runtime cost>" sim --trace "$tmp/good.jsonl" --hardware "$tmp/rt_neg.toml" --out "$tmp/x"
expect_error "sim --pipeline bogus" sim --trace "$tmp/good.jsonl" --pipeline bogus --out "$tmp/x"
expect_error "sim --pipeline runtime --depth 3" sim --trace "$tmp/good.jsonl" --pipeline runtime --depth 3 --out "$tmp/x"
expect_error "sim --pipeline runtime --net dialup" sim --trace "$tmp/good.jsonl" --pipeline runtime --net dialup --out "$tmp/x"
expect_error "sim --pipeline runtime --design static" sim --trace "$tmp/good.jsonl" --pipeline runtime --design static --out "$tmp/x"
expect_error "calibrate without --out" calibrate
expect_error "calibrate --profile /nonexistent.toml" calibrate --profile /nonexistent.toml --out "$tmp/cal.toml"
expect_error "calibrate --codec bogus" calibrate --codec bogus --out "$tmp/cal.toml"
expect_error "run --hardware /nonexistent" run --hardware /nonexistent.toml --frames 2 --out "$tmp/run"
expect_error "run --quality-every -1" run --quality-every -1 --frames 2 --out "$tmp/run"
expect_error "run --hardware <bad runtime.pipeline>" run --hardware "$tmp/rt_bad.toml" --frames 2 --out "$tmp/run"
# --headsets (1..16) and --headset-offset-ms ([0, 1000]) are bounded: a bad value exits 2, naming
# its option, before anything runs.
for bad in "headsets 0" "headsets 17" "headsets x" "headset-offset-ms -1" "headset-offset-ms nan" \
    "headset-offset-ms 1001"; do
    set -- $bad
    others=()
    [ "$1" = headsets ] || others=(--headsets 2)
    "$QVR" run "${others[@]}" "--$1" "$2" --frames 2 --out "$tmp/run" >/dev/null 2>"$tmp/bad_err.txt"
    rc=$?
    if [ $rc -eq 2 ] && grep -q -- "--$1" "$tmp/bad_err.txt"; then
        pass "run --$1 $2 exits 2"
    else
        fail "run --$1 $2 exits 2" "exit $rc: $(head -c 200 "$tmp/bad_err.txt")"
    fi
done
# qvr capacity: a calibration and a workload are required; bad values exit 2.
for args in "--trace x --target-fps 30" \
    "--hardware /nonexistent.toml --trace x --target-fps 30" \
    "--hardware $tmp/rt_bad.toml --trace $tmp/rt_bad.toml --target-fps 0" \
    "--hardware $tmp/rt.toml --trace $tmp/good.jsonl --target-fps 5 --headset-speed 0" \
    "--hardware $tmp/rt.toml --trace $tmp/good.jsonl --target-fps 5 --server-speed nan"; do
    # shellcheck disable=SC2086
    "$QVR" capacity $args >/dev/null 2>"$tmp/bad_err.txt"
    rc=$?
    if [ $rc -eq 2 ] && [ -s "$tmp/bad_err.txt" ]; then
        pass "capacity $args exits 2"
    else
        fail "capacity $args exits 2" "exit $rc"
    fi
done
# --scene counts the layers' drawn triangles at the trace's poses: a scene that cannot load exits 2
# naming the option; one that loads gives a count.
expect_error "capacity --scene /nonexistent.glb" capacity --hardware "$tmp/rt.toml" \
    --trace "$tmp/good.jsonl" --target-fps 5 --max-headsets 2 --frames 20 --scene /nonexistent.glb
if ! grep -q -- "--scene" "$tmp/bad_err.txt"; then
    fail "capacity --scene /nonexistent.glb names --scene" "$(head -c 200 "$tmp/bad_err.txt")"
fi
if run_ok "capacity --scene builtin:room" capacity --hardware "$tmp/rt.toml" \
    --trace "$tmp/good.jsonl" --target-fps 5 --max-headsets 2 --frames 20 --scene builtin:room; then
    if grep -q "headsets per server at 5 FPS" "$tmp/out.json"; then
        pass "capacity --scene builtin:room gives a count"
    else
        fail "capacity --scene builtin:room gives a count" "$(head -c 300 "$tmp/out.json")"
    fi
fi
expect_error "validate --depths 3" validate --depths 3 --dry-run --out "$tmp/val"
expect_error "validate --frames 2" validate --frames 2 --dry-run --out "$tmp/val"
expect_error "validate --reps 0" validate --reps 0 --dry-run --out "$tmp/val"
expect_error "validate --scenes ''" validate --scenes "" --dry-run --out "$tmp/val"
expect_error "validate --retakes 6" validate --retakes 6 --dry-run --out "$tmp/val"
expect_error "validate --retakes -1" validate --retakes -1 --dry-run --out "$tmp/val"
expect_error "validate --hardware /nonexistent" validate --hardware /nonexistent.toml --scenes builtin:room --dry-run --out "$tmp/val"
expect_error "validate --hardware with two scenes" validate --hardware "$tmp/rt_bad.toml" --dry-run --out "$tmp/val"
if run_ok "validate --dry-run lists its commands" validate --dry-run --links wifi,lte --scenes builtin:room --depths 1,2 --out "$tmp/val"; then
    if [ "$(grep -c ' run --scene' "$tmp/out.json")" -eq 4 ] && grep -q ' calibrate --scene' "$tmp/out.json"; then
        pass "validate plans one calibration and 2 links x 2 depths runs"
    else
        fail "validate plans one calibration and 2 links x 2 depths runs" "$(head -c 600 "$tmp/out.json")"
    fi
fi
expect_error "validate --calibrate twice" validate --calibrate twice --dry-run --out "$tmp/val"
# Each repetition calibrates each scene anew, before its runs, and predicts them with that
# calibration; `--calibrate once` keeps one per scene for every repetition.
if run_ok "validate --reps 2 --dry-run" validate --dry-run --reps 2 --links wifi --scenes builtin:room --depths 1 --out "$tmp/val"; then
    if [ "$(grep -c ' calibrate --scene' "$tmp/out.json")" -eq 2 ] &&
        grep -A1 'depth 1 | rep 2 \.\.\.' "$tmp/out.json" | grep -q "hardware '[^']*calibration-builtin_room-r2.toml'" &&
        grep -A1 'depth 1 | rep 1 \.\.\.' "$tmp/out.json" | grep -q "hardware '[^']*calibration-builtin_room.toml'" &&
        [ "$(grep -n 'calibrating on builtin:room for rep 2' "$tmp/out.json" | cut -d: -f1)" -gt \
          "$(grep -n 'depth 1 | rep 1 \.\.\.' "$tmp/out.json" | cut -d: -f1)" ]; then
        pass "validate calibrates anew for each repetition, before that repetition's runs"
    else
        fail "validate calibrates anew for each repetition" "$(head -c 900 "$tmp/out.json")"
    fi
fi
if run_ok "validate --reps 2 --calibrate once --dry-run" validate --dry-run --reps 2 --calibrate once --links wifi --scenes builtin:room --depths 1 --out "$tmp/val"; then
    if [ "$(grep -c ' calibrate --scene' "$tmp/out.json")" -eq 1 ] &&
        [ "$(grep -c "hardware '[^']*calibration-builtin_room.toml'" "$tmp/out.json")" -eq 2 ]; then
        pass "validate --calibrate once predicts every repetition with one calibration"
    else
        fail "validate --calibrate once" "$(head -c 900 "$tmp/out.json")"
    fi
fi

# qvr sweep: bad options exit 2 with a message; a dry run draws the same conditions from a seed.
expect_error "sweep --conditions 0" sweep --conditions 0 --dry-run --out "$tmp/sw"
expect_error "sweep --share-min 0" sweep --share-min 0 --dry-run --out "$tmp/sw"
expect_error "sweep --rate-min over --rate-max" sweep --rate-min 50 --rate-max 5 --dry-run --out "$tmp/sw"
expect_error "sweep --fixed-grid 0.5" sweep --fixed-grid 2,0.5 --dry-run --out "$tmp/sw"
expect_error "sweep --designs without qvr" sweep --designs sw,ffr --dry-run --out "$tmp/sw"
expect_error "sweep --traces /nonexistent" sweep --traces /nonexistent.down --dry-run --out "$tmp/sw"
expect_error "sweep --motions /nonexistent" sweep --motions /nonexistent.bvh --dry-run --out "$tmp/sw"
"$QVR" sweep --repeats 21 --dry-run --out "$tmp/sw" >/dev/null 2>&1
rc=$?
[ $rc -eq 2 ] && pass "sweep --repeats 21 exits 2" || fail "sweep --repeats 21 exits 2" "exit $rc"
if run_ok "sweep --dry-run draws its conditions" sweep --dry-run --seed 5 --conditions 3 --scenes builtin:room --motions default --traces "" --out "$tmp/sw"; then
    cp "$tmp/out.json" "$tmp/sweep1.txt"
    if run_ok "sweep --dry-run again" sweep --dry-run --seed 5 --conditions 3 --scenes builtin:room --motions default --traces "" --out "$tmp/sw" &&
        cmp -s "$tmp/out.json" "$tmp/sweep1.txt" &&
        [ "$(grep -c 'builtin:room | rate:' "$tmp/out.json")" -eq 3 ] &&
        grep -q 'fixed:20' "$tmp/out.json"; then
        pass "sweep draws the same 3 conditions from the same seed"
    else
        fail "sweep draws the same 3 conditions from the same seed" "$(head -c 600 "$tmp/out.json")"
    fi
fi
# qvr validate out of sample: one scene calibrated for two, motions and headset shares.
expect_error "validate --headset-shares 1.5" validate --headset-shares 1.5 --dry-run --out "$tmp/val"
expect_error "validate --motions /nonexistent" validate --motions /nonexistent.bvh --dry-run --out "$tmp/val"
if run_ok "validate --calibration-scene --dry-run" validate --dry-run --links rate:2.5 --scenes builtin:room,openarena:oa_dm5 --calibration-scene builtin:room --headset-shares 1,0.5 --depths 2 --out "$tmp/val"; then
    if [ "$(grep -c ' calibrate --scene' "$tmp/out.json")" -eq 1 ] &&
        [ "$(grep -c ' run --scene' "$tmp/out.json")" -eq 4 ] &&
        [ "$(grep -c -- '--headset-share 0.5' "$tmp/out.json")" -eq 2 ]; then
        pass "validate --calibration-scene predicts two scenes at two shares with one calibration"
    else
        fail "validate --calibration-scene" "$(head -c 900 "$tmp/out.json")"
    fi
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
