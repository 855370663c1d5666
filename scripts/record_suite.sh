#!/usr/bin/env bash
# Records the default workload suite that `qvr eval` replays (docs/RECORDING.md; paper Table 3):
# every level given at 1920x2160, the first two also at 1280x1600, into data/workloads/ with a
# suite.txt that lists them in order. Works with any OpenArena level (openarena:NAME) and any
# scene named in full (builtin:room, FILE.obj).
#
#   scripts/record_suite.sh [--frames N] [--out DIR] [--qvr PATH] [--jobs N] LEVEL...
#   scripts/record_suite.sh --jobs 2 --frames 120 oa_dm5 builtin:room oa_dm1 oasago2 ps37ctf
#                                                                       (the committed suite)
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
frames=300
out="$here/data/workloads"
qvr="$here/build/record/apps/qvr/qvr"
jobs=1
levels=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --frames) frames="$2"; shift 2 ;;
        --out) out="$2"; shift 2 ;;
        --qvr) qvr="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
        -*) echo "record_suite.sh: unknown option $1" >&2; exit 2 ;;
        *) levels+=("$1"); shift ;;
    esac
done
if [[ ${#levels[@]} -lt 2 ]]; then
    echo "record_suite.sh: give at least two levels or scenes (e.g. oa_dm5 builtin:room ...)" >&2
    exit 2
fi
if [[ ! -x "$qvr" ]]; then
    echo "record_suite.sh: no qvr at $qvr (build it, or pass --qvr PATH)" >&2
    exit 2
fi
mkdir -p "$out"

# Head motion: the three recordings of assimp-testmodels in turn, so levels differ in motion as
# well as content; gaze: a seed per workload.
bvh_dir=/usr/share/assimp/models/BVH
motions=("$bvh_dir/01_01.bvh" "$bvh_dir/01_03.bvh" "$bvh_dir/Boxing_Toes.bvh")

# One line per workload: name, level, profile, motion, gaze seed.
plan=()
seed=1
for i in "${!levels[@]}"; do
    level="${levels[$i]}"
    if [[ "$level" == *:* ]]; then
        # A scene named in full (builtin:room): its name after the colon.
        base="${level##*:}"
        base="${base##*/}"
        base="${base%.*}"
    else
        base="oa-${level//_/-}"
        base="${base/oa-oa-/oa-}"
    fi
    motion="${motions[$((i % 3))]}"
    plan+=("$base-h $level default $motion $seed")
    seed=$((seed + 1))
    if [[ $i -lt 2 ]]; then
        plan+=("$base-l $level low $motion $seed")
        seed=$((seed + 1))
    fi
done

record() {
    local name="$1" level="$2" profile="$3" motion="$4" gaze_seed="$5"
    local start end
    start=$(date +%s)
    local scene="openarena:$level"
    [[ "$level" == *:* ]] && scene="$level"
    "$qvr" trace record --scene "$scene" --profile "$profile" --motion "$motion" \
        --gaze-seed "$gaze_seed" --frames "$frames" --name "$name" \
        --out "$out/$name.jsonl.part" > "$out/$name.log" 2>&1
    mv "$out/$name.jsonl.part" "$out/$name.jsonl"
    end=$(date +%s)
    echo "$name: $((end - start)) s, $(wc -c < "$out/$name.jsonl") bytes"
}
export -f record
export qvr frames out

printf '%s\n' "${plan[@]}" | xargs -P "$jobs" -L 1 bash -c 'record "$@"' _

# The suite in recording order; `qvr eval` reads this list (sim/src/benches.cpp).
{
    echo "# name level profile motion gaze_seed frames (written by scripts/record_suite.sh)"
    for line in "${plan[@]}"; do
        echo "$line $frames"
    done
} > "$out/suite.txt"
rm -f "$out"/*.log
echo "suite of ${#plan[@]} workloads in $out"
