#!/usr/bin/env bash
# The first of the README's two commands: install what is missing, build the release preset,
# and run qvr's main job on its embedded defaults — `qvr run` (a render server and a headset
# client on loopback, every design for the same frames) and then `qvr eval` (the paper's
# evaluation in the simulator). Outputs go to qvr-out/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
qvr_install_deps
cmake --preset release -DQVR_BUILD_TESTS=OFF -DQVR_BUILD_BENCH=OFF
cmake --build --preset release --target qvr
qvr=./build/release/apps/qvr/qvr
"$qvr" run --out qvr-out/run
"$qvr" eval --out qvr-out/eval
echo
echo "qvr: done. Open qvr-out/run/report.html (the runtime) and qvr-out/eval/report.html (the simulator)."
