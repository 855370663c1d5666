// The scalar twin of the UCA tile kernel (paper §4.2, Eq. 4): one pixel at a time, the same
// arithmetic in the same order as the Highway kernel (std::fma wherever it fuses), so tests can
// require the two to agree bit for bit.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "uca_kernel.h"

namespace qvr::detail {

namespace {

struct Mapped {
    float px = 0, py = 0;  // rendered-image point, full-resolution pixels
    float cos_e = 1;       // cosine of the eccentricity from the gaze
    bool valid = false;
};

// Steps 1–4 of docs/UCA.md for one pixel of a row (see RowMap).
Mapped mapPixel(const KernelParams& p, const RowMap& r, float u, float v, float chroma) {
    Mapped m;
    const float xt = std::fma(u, p.ax, p.bx);
    float rx, ry, rz;
    if (p.identity_map) {
        rx = xt;
        ry = r.yt;
        rz = -1.0f;
        m.px = u + 0.5f;
        m.py = v + 0.5f;
        m.valid = true;
    } else {
        const float r2 = std::fma(xt, xt, r.yt2);
        const float poly = std::fma(p.k2, r2, p.k1);
        float f = std::fma(poly, r2, 1.0f);
        if (chroma != 1.0f)
            f *= chroma;
        const float num_x = std::fma(f, std::fma(xt, r.mx, r.cx_row), -r.ox);
        const float num_y = std::fma(f, std::fma(xt, r.my, r.cy_row), -r.oy);
        const float depth = std::fma(-f, std::fma(xt, r.mz, r.cz_row), r.dz);
        if (depth > 1e-6f) {
            const float iz = 1.0f / depth;
            m.px = std::fma(num_x, iz, p.cx);
            m.py = std::fma(num_y, iz, p.cy);
            m.valid = m.px >= 0.0f && m.px <= p.width && m.py >= 0.0f && m.py <= p.height;
        }
        if (!m.valid) {
            m.px = 0.0f;
            m.py = 0.0f;
        }
        rx = num_x * (1.0f / p.fx);
        ry = num_y * (-1.0f / p.fy);
        rz = -depth;
    }
    const float n2 = std::fma(rx, rx, std::fma(ry, ry, rz * rz));
    const float dot = std::fma(p.gaze[0], rx, std::fma(p.gaze[1], ry, p.gaze[2] * rz));
    m.cos_e = dot / std::sqrt(n2);
    return m;
}

uint32_t loadTexel(const KernelLayer& l, int index) {
    uint32_t t;
    std::memcpy(&t, l.texels + static_cast<size_t>(index) * 4, sizeof t);
    return t;
}

// q = −128·(bilinear value) of channels 0–3 of one layer at a rendered-image point, in the
// vector kernel's fixed point.
void sampleLayer(const KernelLayer& l, float px, float py, int q[4]) {
    // Clamping the texel coordinate to [0, size − 1] is clamp-to-edge: at the edge the weight
    // of the tap beyond it is 0 (or the left tap stops one short and the right one weighs 1).
    const float max_x = static_cast<float>(l.width - 1);
    const float max_y = static_cast<float>(l.height - 1);
    const float xq = std::min(
        std::max(std::fma(px, l.inv_scale * kSubTexel, l.offset_x * kSubTexel), 0.0f),
        max_x * kSubTexel);
    const int xi = static_cast<int>(xq + 0.5f);
    const int x0 = std::min(xi >> 7, std::max(l.width - 2, 0));
    const int wx = xi - (x0 << 7);
    const float ly = std::min(std::max(std::fma(py, l.inv_scale, l.offset_y), 0.0f), max_y);
    const float fly = std::min(std::floor(ly), std::max(max_y - 1.0f, 0.0f));
    const float wy = ly - fly;
    const int wy15 = static_cast<int>(std::min(wy * kWeightOne + 0.5f, kWeightOne - 1.0f));
    const int i00 = static_cast<int>(fly * static_cast<float>(l.width)) + x0;
    const int dx = l.width >= 2 ? 1 : 0;
    const int dy = l.height >= 2 ? l.width : 0;
    const uint32_t t[4] = {loadTexel(l, i00), loadTexel(l, i00 + dx), loadTexel(l, i00 + dy),
                           loadTexel(l, i00 + dy + dx)};
    for (int c = 0; c < 4; ++c) {
        auto ch = [&](uint32_t texel) { return static_cast<int>((texel >> (8 * c)) & 0xFFu); };
        const int top = -(ch(t[0]) * (kSubTexel - wx) + ch(t[1]) * wx);
        const int bottom = -(ch(t[2]) * (kSubTexel - wx) + ch(t[3]) * wx);
        q[c] = top + (((bottom - top) * wy15 + (1 << 14)) >> 15);
    }
}

// Eq. 4's ramp share t in 1/32768 steps.
int rampWeight(float c_hi, float inv, float cos_e) {
    const float t = std::min(std::max((c_hi - cos_e) * inv, 0.0f), 1.0f);
    return static_cast<int>(t * kWeightOne + 0.5f);
}

// a + (b − a)·t in the kernel's fixed point; t = 1 is exactly b.
int lerpQ(int t, int a, int b) {
    return t == kWeightOne ? b : a + (((b - a) * t + (1 << 14)) >> 15);
}

// Eq. 4 for one pixel as bytes (alpha included); false off the rendered image.
bool shade(const KernelParams& p, const RowMap& r, float u, float v, float chroma,
           uint8_t slot_mask, uint8_t rgba[4]) {
    const Mapped m = mapPixel(p, r, u, v, chroma);
    int q[4] = {0, 0, 0, 0};
    if ((slot_mask & (slot_mask - 1)) == 0) {
        const int k = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        sampleLayer(p.slots[k], m.px, m.py, q);
    } else {
        // ω₀ = 1 − t₀, ω₁ = t₀(1 − t₁), ω₂ = t₀t₁ as nested lerps; a layer whose weight is 0 is
        // not sampled (its value is ignored exactly).
        const int t0 = rampWeight(p.border_c_hi[0], p.border_inv[0], m.cos_e);
        const int t1 = rampWeight(p.border_c_hi[1], p.border_inv[1], m.cos_e);
        int s[3][4] = {};
        const bool need[3] = {t0 < kWeightOne, t0 > 0 && t1 < kWeightOne, t0 > 0 && t1 > 0};
        for (int k = 0; k < p.slot_count; ++k) {
            if ((slot_mask & (1u << k)) != 0 && need[k])
                sampleLayer(p.slots[k], m.px, m.py, s[k]);
        }
        for (int c = 0; c < 4; ++c)
            q[c] = lerpQ(t0, s[0][c], lerpQ(t1, s[1][c], s[2][c]));
    }
    for (int c = 0; c < 4; ++c)
        rgba[c] = static_cast<uint8_t>((64 - q[c]) >> 7);
    return m.valid;
}

}  // namespace

void ucaTileScalar(const KernelParams& p, const TileJob& job) {
    const float scales[3] = {1.0f, p.chroma_red, p.chroma_blue};
    const int channel_of[3] = {1, 0, 2};  // green from the unscaled map, then red, then blue
    for (int y = job.y0; y < job.y1; ++y) {
        uint8_t* row = job.out + static_cast<size_t>(y) * job.out_stride_px * 4;
        const float v = static_cast<float>(y);
        const RowMap r = rowMap(p, v);
        for (int x = job.x0; x < job.x1; ++x) {
            const float u = static_cast<float>(x);
            uint32_t packed = kOpaqueBlack;
            if (job.slot_mask != 0) {
                uint8_t rgba[4];
                if (!p.chroma) {
                    if (shade(p, r, u, v, 1.0f, job.slot_mask, rgba)) {
                        packed |= uint32_t{rgba[0]} | (uint32_t{rgba[1]} << 8) |
                                  (uint32_t{rgba[2]} << 16);
                    }
                } else {
                    // Lateral chromatic aberration: each channel has its own map and validity.
                    for (int c = 0; c < 3; ++c) {
                        if (shade(p, r, u, v, scales[c], job.slot_mask, rgba)) {
                            const int ch = channel_of[c];
                            packed |= uint32_t{rgba[ch]} << (8 * ch);
                        }
                    }
                }
            }
            std::memcpy(row + static_cast<size_t>(x) * 4, &packed, sizeof packed);
        }
    }
}

}  // namespace qvr::detail
