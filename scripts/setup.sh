#!/usr/bin/env bash
# The first of the README's two commands: install what is missing, build the release preset,
# and run qvr's main job on its embedded defaults.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
qvr_install_deps
cmake --preset release -DQVR_BUILD_TESTS=OFF -DQVR_BUILD_BENCH=OFF
cmake --build --preset release --target qvr
./build/release/apps/qvr/qvr control --policy liwc --frames 300 --compare
