#!/usr/bin/env bash
# Installs the Debian packages qvr needs, only those missing. Sourced by setup.sh and test.sh.
# The list is the single place a new dependency is added.
set -euo pipefail

QVR_PACKAGES=(
    build-essential cmake ninja-build pkg-config git
    libfmt-dev libspdlog-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libglm-dev
    libtbb-dev libhwy-dev libpng-dev
    libgtest-dev libgmock-dev libbenchmark-dev
    gnuplot-nox python3  # report figures; python3 for scripts/claim_matrix_table.py
    libasio-dev libsodium-dev  # net: transport (standalone asio), PSK handshake (HMAC-SHA-256)
    libisal-dev  # net: Reed-Solomon FEC on the media streams (Intel ISA-L)
    # scene: pk3 (zip) archives, glTF/OBJ, JPEG/TGA textures; the OpenArena levels and their
    # textures (assimp-testmodels is listed with trace below)
    libzip-dev libassimp-dev libstb-dev
    openarena-081-maps openarena-081-textures openarena-data
    # codec: H.264 through libavcodec + libx264, the display video as MP4 through libavformat;
    # trace: CMU motion capture (BVH) for head motion
    libavcodec-dev libavformat-dev libavutil-dev libswscale-dev libx264-dev assimp-testmodels
    # render: headless OpenGL 4.5 through EGL (GLVND headers and loaders, Mesa's EGL and llvmpipe)
    libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
    # compose: libopencv-dev only for the optional QVR_WITH_OPENCV benchmark anchor, not listed
)

qvr_install_deps() {
    local missing=()
    for p in "${QVR_PACKAGES[@]}"; do
        if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
            missing+=("$p")
        fi
    done
    if [ ${#missing[@]} -eq 0 ]; then
        echo "qvr: all ${#QVR_PACKAGES[@]} Debian packages present"
        return 0
    fi
    echo "qvr: installing ${missing[*]}"
    local sudo=()
    if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing[@]}"
}
