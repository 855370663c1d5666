#!/usr/bin/env bash
# Shared periphery's cost (docs/RUNTIME.md §Shared periphery): two headsets of one motion and gaze
# on one server, without sharing and with it, alternated per round so the host's drift falls on
# both. Prints each round's server time per headset-frame, their ratio, and the gate's SSIM by
# band. OFFSET_MS > 0: the second headset plays the motion that far ahead (qvr run
# --headset-offset-ms), so the two never share a pose and nothing is copied.
#   bash scripts/shared_periphery_ab.sh QVR OUT [ROUNDS=3] [MODE=on|auto] [DESIGN=fixed:5]
#        [OFFSET_MS=0]
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 QVR OUT [ROUNDS] [MODE] [DESIGN] [OFFSET_MS]" >&2
    exit 2
fi
qvr=$1 out=$2 rounds=${3:-3} mode=${4:-on} design=${5:-fixed:5} offset=${6:-0}
case $mode in on | auto) ;; *) echo "$0: MODE '$mode': expected on or auto" >&2; exit 2 ;; esac
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "$0: ROUNDS '$rounds': expected a count" >&2; exit 2; }
mkdir -p "$out"
for r in $(seq 1 "$rounds"); do
    order="off $mode"
    [ $((r % 2)) = 0 ] && order="$mode off"
    for m in $order; do
        "$qvr" run --scene builtin:room --designs "$design" --profile small --frames 90 \
            --headset-share 0.25 --headsets 2 --identical-workloads --no-video --quality-every 0 \
            --headset-offset-ms "$offset" --share-periphery "$m" --quiet --out "$out/r$r/$m" \
            >"$out/r$r.$m.log" 2>&1
    done
done
python3 - "$out" "$rounds" "$mode" <<'PY'
import json, sys
out, rounds, mode = sys.argv[1], int(sys.argv[2]), sys.argv[3]
for r in range(1, rounds + 1):
    off, on = (json.load(open(f"{out}/r{r}/{m}/summary.json")) for m in ("off", mode))
    sp = on["server"]["share_periphery"]
    a, b = off["server_ms_per_headset_frame"], on["server_ms_per_headset_frame"]
    print(f"round {r}: off {a:.2f} ms, {mode} {b:.2f} ms: {b / a:.2f}x; layers own/shared/reused "
          f"outer {sp['outer_layers_own']}/{sp['outer_layers_shared']}/{sp['outer_layers_reused']} "
          f"middle {sp['middle_layers_own']}/{sp['middle_layers_shared']}/{sp['middle_layers_reused']}; "
          f"group texels {sp['group_texels_per_own']:.2f}x own, margin {sp['margin_deg_mean']:.2f} deg; "
          f"gate failed {sp['measurements_failed']}/{sp['measurements']}")
    for band in sp["ssim_by_band"]:
        print(f"  {band['layer']} {band['lo_deg']:.0f}-{band['hi_deg']:.0f} deg: SSIM mean "
              f"{band['ssim_mean']:.3f}, min {band['ssim_min']:.3f} ({band['measurements']})")
PY
