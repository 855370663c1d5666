// Synthetic layer images for the codec's tests, benchmark and docs (paper §3.2): detail the encoder
// must keep, flat areas it should compress away, and noise it cannot.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "qvr/core/image.h"

namespace qvr {

// Smooth gradients, a sine grating, hard-edged blocks and a little grain: like a rendered,
// textured scene, with detail at several scales. `phase` shifts it to make motion. The hard
// edges are luminance edges and colour changes are smooth, as in shaded scenes; saturated colour
// edges would measure 4:2:0 chroma subsampling (≈30 dB on their own) rather than the codec.
inline ImageRgba8 syntheticDetailedImage(int width, int height, int phase = 0, uint32_t seed = 7) {
    ImageRgba8 img(width, height);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> grain(-6, 6);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const int xs = x + phase;
            const double u = static_cast<double>(xs) / 37.0;
            const double v = static_cast<double>(y) / 23.0;
            const double wave = 60.0 * std::sin(u * 1.7 + v * 0.6) * std::cos(v * 1.3);
            const bool block = ((xs / 24) + (y / 24)) % 3 == 0;
            const int edge = block ? 60 : 0;
            const int r = static_cast<int>(90 + wave + edge) + grain(rng);
            const int g = static_cast<int>(70 + 0.3 * (xs % 256) + edge) + grain(rng);
            const int b = static_cast<int>(120 - wave * 0.5 + 0.2 * (y % 256) + edge) + grain(rng);
            img.at(x, y, 0) = static_cast<uint8_t>(std::clamp(r, 0, 255));
            img.at(x, y, 1) = static_cast<uint8_t>(std::clamp(g, 0, 255));
            img.at(x, y, 2) = static_cast<uint8_t>(std::clamp(b, 0, 255));
            img.at(x, y, 3) = 255;
        }
    }
    return img;
}

inline ImageRgba8 syntheticFlatImage(int width, int height, uint8_t r = 90, uint8_t g = 120,
                                     uint8_t b = 160) {
    ImageRgba8 img(width, height);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            img.at(x, y, 0) = r;
            img.at(x, y, 1) = g;
            img.at(x, y, 2) = b;
            img.at(x, y, 3) = 255;
        }
    }
    return img;
}

inline ImageRgba8 syntheticNoiseImage(int width, int height, uint32_t seed = 11) {
    ImageRgba8 img(width, height);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> d(0, 255);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < 3; ++c)
                img.at(x, y, c) = static_cast<uint8_t>(d(rng));
            img.at(x, y, 3) = 255;
        }
    }
    return img;
}

}  // namespace qvr
