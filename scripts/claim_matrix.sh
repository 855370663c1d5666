#!/usr/bin/env bash
# Issue 15's matrix: does adaptive foveation (qvr) beat every fixed fovea in the real runtime?
# For each condition (scene × link × headset share) it runs the fixed sweep
# e1 ∈ {2,5,10,15,20,30}° once (with sw and qvr), picks the best fixed e1 in hindsight, then runs
# ffr, sw, qvr and that best fixed e1 twice more, and writes a table of medians with their
# spread (min–max over the three runs) to OUT/matrix.md and OUT/matrix.json. The host's speed
# drifts, so every run takes its designs in another order (the sweep reversed on odd conditions,
# the repeats rotated by one design each).
#
#   bash scripts/claim_matrix.sh [OUT] [--frames N] [--quick]
#
# --quick runs one condition per link kind (for a check, not for the numbers). About an hour
# on a 2-core machine for the full matrix (14 conditions); run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
out=qvr-matrix
frames=150
quick=0
while [ $# -gt 0 ]; do
    case "$1" in
        --frames) frames="$2"; shift 2 ;;
        --quick) quick=1; shift ;;
        -*) echo "claim_matrix: unknown option $1" >&2; exit 2 ;;
        *) out="$1"; shift ;;
    esac
done
case "$frames" in ''|*[!0-9]*) echo "claim_matrix: --frames needs a whole number" >&2; exit 2 ;; esac
qvr=${QVR:-./build/release/apps/qvr/qvr}
if [ ! -x "$qvr" ]; then
    echo "claim_matrix: $qvr not built (cmake --preset release && cmake --build --preset release)" >&2
    exit 2
fi
traces=${QVR_TRACES:-../shared/data/network}
for t in ATT-LTE-driving-2016.down TMobile-LTE-short.down Verizon-LTE-short.down; do
    [ -f "$traces/$t" ] || { echo "claim_matrix: missing trace $traces/$t" >&2; exit 2; }
done
mkdir -p "$out"
conditions=()
for share in 1.0 0.6; do
    for link in wifi lte 5g "trace:$traces/ATT-LTE-driving-2016.down" \
        "trace:$traces/TMobile-LTE-short.down" "trace:$traces/Verizon-LTE-short.down"; do
        conditions+=("builtin:room|$link|$share")
    done
done
conditions+=("openarena:oa_dm5|wifi|1.0" "openarena:oa_dm5|trace:$traces/ATT-LTE-driving-2016.down|1.0")
if [ "$quick" = 1 ]; then
    conditions=("builtin:room|wifi|1.0" "builtin:room|trace:$traces/ATT-LTE-driving-2016.down|1.0")
fi
sweep=fixed:2,fixed:5,fixed:10,fixed:15,fixed:20,fixed:30,sw,qvr
# A comma list rotated left by N designs.
rotated() { python3 -c "import sys; d=sys.argv[1].split(','); n=int(sys.argv[2])%len(d); print(','.join(d[n:]+d[:n]))" "$1" "$2"; }
start=$(date +%s)
index=0
for c in "${conditions[@]}"; do
    index=$((index + 1))
    IFS='|' read -r scene link share <<<"$c"
    name=$(echo "${scene}_${link##*/}_${share}" | tr ':/' '__')
    echo "== $scene $link share $share"
    common=(--scene "$scene" --net "$link" --headset-share "$share" --frames "$frames" --no-video
        --quality-every 0 --quiet)
    first=$sweep
    [ $((index % 2)) = 1 ] && first=$(echo "$sweep" | tr ',' '\n' | tac | paste -sd,)
    "$qvr" run "${common[@]}" --designs "$first" --out "$out/$name/run1" | grep -E '^  [a-z]'
    best=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['best_fixed']['design'])" \
        "$out/$name/run1/summary.json")
    designs=ffr,sw,qvr
    [ "$best" != fixed:5 ] && designs="$designs,$best"
    for rep in 2 3; do
        "$qvr" run "${common[@]}" --designs "$(rotated "$designs" $((rep - 1 + index)))" --out "$out/$name/run$rep" | grep -E '^  [a-z]'
    done
done
echo "matrix: $(( $(date +%s) - start )) s"
python3 scripts/claim_matrix_table.py "$out"
