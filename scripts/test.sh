#!/usr/bin/env bash
# The second of the README's two commands: install what is missing, build everything with
# warnings as errors, and run the whole default test suite (long soaks carry the label "soak"
# and run only with QVR_SOAK=1).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
qvr_install_deps
preset=${QVR_PRESET:-dev}
# Mesa's llvmpipe is installed by deps.sh, so a GL test that cannot get a context is a failure
# here, not a skip.
export QVR_REQUIRE_GL=${QVR_REQUIRE_GL:-1}
cmake --preset "$preset"
cmake --build --preset "$preset" -j "$(nproc)"
if [ "${QVR_SOAK:-0}" = 1 ]; then
    ctest --test-dir "build/$preset" --output-on-failure -j "$(nproc)"
else
    ctest --preset "$preset" -j "$(nproc)"
fi
