#!/usr/bin/env bash
# The second of the README's two commands: install what is missing, build everything with
# warnings as errors, and run the whole default test suite (long soaks carry the label "soak"
# and run only with QVR_SOAK=1). Then the same suite again built with AddressSanitizer +
# UBSan (the asan preset), and the network and runtime tests built with ThreadSanitizer (the
# tsan preset); QVR_SANITIZERS=0 skips both, CI never does. Any failure in any suite, a
# sanitizer report included, fails the script.
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
# The sanitizer suite (docs/FUZZING.md §Sanitizers): after the default one, so a plain failure
# is reported before the asan build and suite. Soaks stay out of it.
if [ "$preset" = dev ] && [ "${QVR_SANITIZERS:-1}" != 0 ]; then
    cmake --preset asan
    cmake --build --preset asan -j "$(nproc)"
    ctest --preset asan -j "$(nproc)"
    # ThreadSanitizer over the network and runtime tests (the threaded parts: transport, render
    # server, headset pipeline); ~5 min more. Only their two test binaries are built.
    cmake --preset tsan
    cmake --build --preset tsan -j "$(nproc)" --target net_tests runtime_tests
    ctest --preset tsan -j "$(nproc)"
fi
