#!/usr/bin/env bash
# Installs the Debian packages qvr needs, only those missing. Sourced by setup.sh and test.sh.
# The list is the single place a new dependency is added.
set -euo pipefail

# What compiles and links qvr (the container image's build stage installs only these).
QVR_BUILD_PACKAGES=(
    build-essential cmake ninja-build pkg-config git
    libfmt-dev libspdlog-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libglm-dev
    libtbb-dev libhwy-dev libpng-dev
    libasio-dev libsodium-dev  # net: transport (standalone asio), PSK handshake (HMAC-SHA-256)
    libisal-dev  # net: Reed-Solomon FEC on the media streams (Intel ISA-L)
    # scene: pk3 (zip) archives, glTF/OBJ, JPEG/TGA textures
    libzip-dev libassimp-dev libstb-dev
    # codec: H.264 through libavcodec + libx264, the display video as MP4 through libavformat
    libavcodec-dev libavformat-dev libavutil-dev libswscale-dev libx264-dev
    # render: headless OpenGL 4.5 through EGL (GLVND headers and loaders, Mesa's EGL and llvmpipe)
    libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
    # compose: libopencv-dev only for the optional QVR_WITH_OPENCV benchmark anchor, not listed
)
# What the built `qvr` loads at run time (the container image's final stage).
QVR_RUNTIME_PACKAGES=(
    libfmt9 libtbb12 libhwy1 libpng16-16 libtomlplusplus3 libsodium23 libisal2 libzip4 libstb0
    libassimp5 libavcodec59 libavformat59 libavutil57 libswscale6 libx264-164
    libegl1 libopengl0 libgl1 libegl-mesa0 libgl1-mesa-dri
)
# Tests, reports, and the real levels and motions of the default run and the test suite.
QVR_TEST_PACKAGES=(
    libgtest-dev libgmock-dev libbenchmark-dev
    gnuplot-nox python3  # report figures; python3 for the scripts
    python3-yaml python3-jsonschema  # the Agones resources' schema check (deploy/agones)
    openarena-081-maps openarena-081-textures openarena-data  # the OpenArena levels
    assimp-testmodels  # trace: CMU motion capture (BVH) for head motion
)
QVR_PACKAGES=("${QVR_BUILD_PACKAGES[@]}" "${QVR_TEST_PACKAGES[@]}")

# qvr_install_deps [PACKAGE...]: installs those named (default: QVR_PACKAGES) that are missing.
qvr_install_deps() {
    local wanted=("$@")
    if [ ${#wanted[@]} -eq 0 ]; then wanted=("${QVR_PACKAGES[@]}"); fi
    local missing=()
    for p in "${wanted[@]}"; do
        if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
            missing+=("$p")
        fi
    done
    if [ ${#missing[@]} -eq 0 ]; then
        echo "qvr: all ${#wanted[@]} Debian packages present"
        return 0
    fi
    echo "qvr: installing ${missing[*]}"
    local sudo=()
    if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing[@]}"
}
