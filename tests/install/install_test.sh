#!/usr/bin/env bash
# `cmake --install` of this build tree into a fresh prefix, then a project outside the tree
# (tests/install/consumer) found through find_package(qvr), built and run: it runs LIWC and UCA.
# The consumer is compiled with the build's compiler and flags (sanitizer builds need them).
# Usage: install_test.sh BUILD_DIR SOURCE_DIR [CXX [CXXFLAGS [LDFLAGS]]]
set -euo pipefail
build=$1
src=$2
cxx=${3:-c++}
cxxflags=${4:-}
ldflags=${5:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
for f in include/qvr/controller/liwc.h include/qvr/compose/uca.h lib/libqvr_controller.a \
         lib/libqvr_compose.a lib/cmake/qvr/qvrConfig.cmake lib/cmake/qvr/qvrTargets.cmake; do
    if [ ! -f "$tmp/prefix/$f" ] && [ ! -f "$tmp/prefix/${f/lib\//lib/x86_64-linux-gnu/}" ]; then
        echo "FAIL: $f not installed"; exit 1
    fi
done
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$src/tests/install/consumer" -B "$tmp/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_CXX_FLAGS="$cxxflags" \
    -DCMAKE_EXE_LINKER_FLAGS="$ldflags" "${launcher[@]}" >"$tmp/configure.log" ||
    { cat "$tmp/configure.log"; echo "FAIL: the consumer does not configure"; exit 1; }
cmake --build "$tmp/consumer" >"$tmp/build.log" ||
    { tail -40 "$tmp/build.log"; echo "FAIL: the consumer does not build"; exit 1; }
"$tmp/consumer/qvr_consumer"
echo "PASS: an installed qvr is found, built against and runs LIWC and UCA"
