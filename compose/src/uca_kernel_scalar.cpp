// The scalar twin of the UCA tile kernel (paper §4.2, Eq. 4): one pixel at a time, the same
// float operations in the same order as the Highway kernel (std::fma wherever it fuses), so tests
// can require the two to agree bit for bit.
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

// Byte c of a texel as the biased float kTexelBias + byte (exact), as the vector kernel forms it.
float channelOf(uint32_t texel, int c) {
    return kTexelBias + static_cast<float>((texel >> (8 * c)) & 0xFFu);
}

// Bilinear, clamp-to-edge, RGB of one layer at a texel coordinate, biased (kTexelBias + value).
void sampleTexels(const KernelLayer& l, float lx_in, float ly_in, float rgb[3]) {
    // Clamping the texel coordinate to [0, size − 1] is clamp-to-edge: at the edge the weight
    // of the tap beyond it is 0, and that tap is redirected onto the edge texel. (The vector
    // kernel's mesh tiles skip the clamps where they change nothing.)
    const float max_x = static_cast<float>(l.width - 1);
    const float max_y = static_cast<float>(l.height - 1);
    const float lx = std::min(std::max(lx_in, 0.0f), max_x);
    const float ly = std::min(std::max(ly_in, 0.0f), max_y);
    float flx = std::floor(lx);
    float fly = std::floor(ly);
    int dx = flx < max_x ? 1 : 0;
    int dy = fly < max_y ? 1 : 0;
    if (l.width >= 2 && l.height >= 2) {
        // The vector kernel's pair fetch: the left tap stops one short of the edge, where the
        // right tap's weight becomes exactly 1 — the same value.
        flx = std::min(flx, max_x - 1.0f);
        fly = std::min(fly, max_y - 1.0f);
        dx = 1;
        dy = 1;
    }
    const float wx = lx - flx;
    const float wy = ly - fly;
    // The texel index is formed in float like the vector kernel's (exact below 2^24 texels).
    const int i00 = static_cast<int>(std::fma(fly, static_cast<float>(l.width), flx));
    const int i01 = i00 + dy * l.width;
    const uint32_t t00 = loadTexel(l, i00);
    const uint32_t t10 = loadTexel(l, i00 + dx);
    const uint32_t t01 = loadTexel(l, i01);
    const uint32_t t11 = loadTexel(l, i01 + dx);
    for (int c = 0; c < 3; ++c) {
        const float a = channelOf(t00, c);
        const float b = channelOf(t10, c);
        const float d = channelOf(t01, c);
        const float e = channelOf(t11, c);
        const float top = std::fma(wx, b - a, a);
        const float bot = std::fma(wx, e - d, d);
        rgb[c] = std::fma(wy, bot - top, top);
    }
}

// Bilinear, clamp-to-edge, biased RGB of one layer at a rendered-image point.
void sampleLayer(const KernelLayer& l, float px, float py, float rgb[3]) {
    sampleTexels(l, std::fma(px, l.inv_scale, l.offset_x), std::fma(py, l.inv_scale, l.offset_y),
                 rgb);
}

// Eq. 4's blend of the slots in slot_mask at a rendered-image point (unbiased values).
void blendSlots(const KernelParams& p, uint8_t slot_mask, float px, float py, float cos_e,
                float rgb[3]) {
    const float t1 = std::min(std::max((p.border_c_hi[0] - cos_e) * p.border_inv[0], 0.0f), 1.0f);
    const float t2 = std::min(std::max((p.border_c_hi[1] - cos_e) * p.border_inv[1], 0.0f), 1.0f);
    const float w[3] = {1.0f - t1, t1 - t1 * t2, t1 * t2};
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    for (int k = 0; k < p.slot_count; ++k) {
        if ((slot_mask & (1u << k)) == 0 || w[k] == 0.0f)
            continue;
        float s[3];
        sampleLayer(p.slots[k], px, py, s);
        for (int c = 0; c < 3; ++c)
            rgb[c] = std::fma(w[k], s[c] - kTexelBias, rgb[c]);
    }
}

// Eq. 4 for one pixel: the slots the tile may touch, weighted by the blend ramps.
bool shade(const KernelParams& p, const RowMap& r, float u, float v, float chroma,
           uint8_t slot_mask, float rgb[3]) {
    const Mapped m = mapPixel(p, r, u, v, chroma);
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!m.valid)
        return false;
    if ((slot_mask & (slot_mask - 1)) == 0) {
        const int k = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        sampleLayer(p.slots[k], m.px, m.py, rgb);
        for (int c = 0; c < 3; ++c)
            rgb[c] -= kTexelBias;
        return true;
    }
    blendSlots(p, slot_mask, m.px, m.py, m.cos_e, rgb);
    return true;
}

uint32_t quantize(float value) {
    // A convex combination of bytes stays within [0, 255], so +0.5 and truncation round it.
    return static_cast<uint32_t>(static_cast<int>(value + 0.5f));
}

// A biased channel (kTexelBias + value, the ½ included) to its rounded byte: bits 8–15.
uint32_t quantizeBiased(float biased) {
    uint32_t bits;
    std::memcpy(&bits, &biased, sizeof bits);
    return (bits >> 8) & 0xFFu;
}

uint32_t packBiased(const float rgb[3]) {
    return kOpaqueBlack | quantizeBiased(rgb[0]) | (quantizeBiased(rgb[1]) << 8) |
           (quantizeBiased(rgb[2]) << 16);
}

// The tile's 9×9 lattice of exact maps (docs/UCA.md, "Mesh tiles"), point by point.
void mapLattice(const KernelParams& p, const TileJob& job, const MeshPlan& plan, MeshLattice& out) {
    const KernelLayer& layer = p.slots[plan.layer];
    for (int k = 0; k < kMeshLatticePoints; ++k) {
        const float u = static_cast<float>(job.x0 + (k % kMeshLatticeSide) * (kMeshStepPx / 2));
        const float v = static_cast<float>(job.y0 + (k / kMeshLatticeSide) * (kMeshStepPx / 2));
        const Mapped m = mapPixel(p, rowMap(p, v), u, v, 1.0f);
        out.px[k] = m.px;
        out.py[k] = m.py;
        out.lx[k] = std::fma(m.px, layer.inv_scale, layer.offset_x);
        out.ly[k] = std::fma(m.py, layer.inv_scale, layer.offset_y);
    }
}

// cos e of a rendered-image point (border mesh tiles), as the vector kernel forms it.
float meshEccentricityCos(const KernelParams& p, float px, float py) {
    const float rx = (px - p.cx) * (1.0f / p.fx);
    const float ry = (p.cy - py) * (1.0f / p.fy);
    const float n2 = std::fma(rx, rx, std::fma(ry, ry, 1.0f));
    const float dot = std::fma(p.gaze[0], rx, std::fma(p.gaze[1], ry, -p.gaze[2]));
    return dot / std::sqrt(n2);
}

// A value of a mesh tile's pixel (c, r): the nodes of its cell interpolated along x on both
// node rows, then along y, in the vector kernel's order.
float meshValue(const float* v, int c, int r) {
    constexpr int n = kMeshLatticeSide;
    const int i = 2 * (c / kMeshStepPx);
    const int j = 2 * (r / kMeshStepPx);
    const float a = static_cast<float>(c % kMeshStepPx) * (1.0f / kMeshStepPx);
    const float b = static_cast<float>(r % kMeshStepPx) * (1.0f / kMeshStepPx);
    const float* top = v + j * n + i;
    const float* bottom = v + (j + 2) * n + i;
    const float h0 = std::fma(top[2] - top[0], a, top[0]);
    const float h1 = std::fma(bottom[2] - bottom[0], a, bottom[0]);
    return std::fma(h1 - h0, b, h0);
}

}  // namespace

bool ucaTileScalar(const KernelParams& p, const TileJob& job) {
    const bool single = job.slot_mask != 0 && (job.slot_mask & (job.slot_mask - 1)) == 0;
    if (job.mesh && job.slot_mask != 0 && !p.identity_map && !p.chroma &&
        job.x1 - job.x0 <= kTilePx && job.y1 - job.y0 <= kTilePx) {
        const MeshPlan plan = meshPlan(p, job.slot_mask);
        MeshLattice lattice;
        bool meshed = plan.usable;
        if (meshed) {
            mapLattice(p, job, plan, lattice);
            meshed = meshAcceptable(lattice, p, plan);
        }
        if (meshed) {
            for (int y = job.y0; y < job.y1; ++y) {
                uint8_t* row = job.out + static_cast<size_t>(y) * job.out_stride_px * 4;
                for (int x = job.x0; x < job.x1; ++x) {
                    const int c = x - job.x0, r = y - job.y0;
                    float rgb[3];
                    uint32_t packed;
                    if (plan.border) {
                        const float px = meshValue(lattice.px, c, r);
                        const float py = meshValue(lattice.py, c, r);
                        blendSlots(p, job.slot_mask, px, py, meshEccentricityCos(p, px, py), rgb);
                        packed = kOpaqueBlack | quantize(rgb[0]) | (quantize(rgb[1]) << 8) |
                                 (quantize(rgb[2]) << 16);
                    } else {
                        sampleTexels(p.slots[plan.layer], meshValue(lattice.lx, c, r),
                                     meshValue(lattice.ly, c, r), rgb);
                        packed = packBiased(rgb);
                    }
                    std::memcpy(row + static_cast<size_t>(x) * 4, &packed, sizeof packed);
                }
            }
            return true;
        }
    }
    for (int y = job.y0; y < job.y1; ++y) {
        uint8_t* row = job.out + static_cast<size_t>(y) * job.out_stride_px * 4;
        const float v = static_cast<float>(y);
        const RowMap r = rowMap(p, v);
        for (int x = job.x0; x < job.x1; ++x) {
            const float u = static_cast<float>(x);
            uint32_t packed = kOpaqueBlack;
            if (job.slot_mask != 0 && !p.chroma && single) {
                // One layer: its biased channels go straight to bytes, as in the vector kernel.
                const Mapped m = mapPixel(p, r, u, v, 1.0f);
                if (m.valid) {
                    float rgb[3];
                    sampleLayer(p.slots[job.slot_mask == 1 ? 0 : (job.slot_mask == 2 ? 1 : 2)],
                                m.px, m.py, rgb);
                    packed = packBiased(rgb);
                }
            } else if (job.slot_mask != 0) {
                float rgb[3];
                if (!p.chroma) {
                    shade(p, r, u, v, 1.0f, job.slot_mask, rgb);
                } else {
                    // Lateral chromatic aberration: each channel has its own radial scale.
                    float tmp[3];
                    shade(p, r, u, v, p.chroma_red, job.slot_mask, tmp);
                    rgb[0] = tmp[0];
                    shade(p, r, u, v, 1.0f, job.slot_mask, tmp);
                    rgb[1] = tmp[1];
                    shade(p, r, u, v, p.chroma_blue, job.slot_mask, tmp);
                    rgb[2] = tmp[2];
                }
                packed |= quantize(rgb[0]) | (quantize(rgb[1]) << 8) | (quantize(rgb[2]) << 16);
            }
            std::memcpy(row + static_cast<size_t>(x) * 4, &packed, sizeof packed);
        }
    }
    return false;
}

}  // namespace qvr::detail
