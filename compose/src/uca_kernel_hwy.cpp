// The vectorised UCA tile kernel (paper §4.2, Eq. 4) with Highway: a vector of display pixels is
// mapped through lens and rotation at once, each layer's four texels are fetched with gathers,
// and Eq. 4's weighted sum runs lane-wise. Dispatches to the best target the CPU has at run time.
// Every fused multiply-add is explicit and the file is built with -ffp-contract=off, so the
// scalar twin (uca_kernel_scalar.cpp) can reproduce it bit for bit on FMA targets.
#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "uca_kernel_hwy.cpp"
#include <hwy/cache_control.h>
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "uca_kernel.h"

// GCC 12 flags the self-initialised _mm512_undefined_*() inside some AVX-512 intrinsics as
// maybe-uninitialized (a known false positive of the compiler's own headers).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

HWY_BEFORE_NAMESPACE();
namespace qvr::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;

struct MapV {
    VF px, py, cos_e;
    MF valid;
};

struct Rgb {
    VF r, g, b;
};

// Float → int32 by truncation for values known to be in range: one instruction, without the
// out-of-range fix-up Highway's ConvertTo adds (three more per conversion).
HWY_INLINE VI truncToInt(VF v) {
    const DI di;
#if HWY_TARGET <= HWY_AVX3
    (void)di;
    return VI{_mm512_cvttps_epi32(v.raw)};
#elif HWY_TARGET == HWY_AVX2
    (void)di;
    return VI{_mm256_cvttps_epi32(v.raw)};
#elif HWY_ARCH_X86 && HWY_TARGET != HWY_SCALAR && HWY_TARGET != HWY_EMU128
    (void)di;
    return VI{_mm_cvttps_epi32(v.raw)};
#else
    return hn::ConvertTo(di, v);
#endif
}

// Steps 1–4 of docs/UCA.md for a vector of pixels of one row (see RowMap). need_cos: only
// border tiles blend by eccentricity; single-layer tiles skip its square root and division.
HWY_INLINE MapV mapPixels(const KernelParams& p, const RowMap& r, VF u, VF v, float chroma,
                          bool need_cos) {
    const DF df;
    const VF xt = hn::MulAdd(u, hn::Set(df, p.ax), hn::Set(df, p.bx));
    VF rx, ry, rz;
    MapV m;
    if (p.identity_map) {
        rx = xt;
        ry = hn::Set(df, r.yt);
        rz = hn::Set(df, -1.0f);
        m.px = hn::Add(u, hn::Set(df, 0.5f));
        m.py = hn::Add(v, hn::Set(df, 0.5f));
        m.valid = hn::Eq(u, u);
    } else {
        const VF r2 = hn::MulAdd(xt, xt, hn::Set(df, r.yt2));
        const VF poly = hn::MulAdd(hn::Set(df, p.k2), r2, hn::Set(df, p.k1));
        VF f = hn::MulAdd(poly, r2, hn::Set(df, 1.0f));
        if (chroma != 1.0f)
            f = hn::Mul(f, hn::Set(df, chroma));
        const VF num_x = hn::MulAdd(f, hn::MulAdd(xt, hn::Set(df, r.mx), hn::Set(df, r.cx_row)),
                                    hn::Set(df, -r.ox));
        const VF num_y = hn::MulAdd(f, hn::MulAdd(xt, hn::Set(df, r.my), hn::Set(df, r.cy_row)),
                                    hn::Set(df, -r.oy));
        const VF depth = hn::NegMulAdd(f, hn::MulAdd(xt, hn::Set(df, r.mz), hn::Set(df, r.cz_row)),
                                       hn::Set(df, r.dz));
        const MF front = hn::Gt(depth, hn::Set(df, 1e-6f));
        const VF iz = hn::Div(hn::Set(df, 1.0f), hn::IfThenElse(front, depth, hn::Set(df, 1.0f)));
        const VF px = hn::MulAdd(num_x, iz, hn::Set(df, p.cx));
        const VF py = hn::MulAdd(num_y, iz, hn::Set(df, p.cy));
        const VF zero = hn::Zero(df);
        const MF in_x = hn::And(hn::Ge(px, zero), hn::Le(px, hn::Set(df, p.width)));
        const MF in_y = hn::And(hn::Ge(py, zero), hn::Le(py, hn::Set(df, p.height)));
        m.valid = hn::And(front, hn::And(in_x, in_y));
        // Invalid lanes sample a harmless point; their colour is replaced by black below.
        m.px = hn::IfThenElseZero(m.valid, px);
        m.py = hn::IfThenElseZero(m.valid, py);
        if (need_cos) {
            rx = hn::Mul(num_x, hn::Set(df, 1.0f / p.fx));
            ry = hn::Mul(num_y, hn::Set(df, -1.0f / p.fy));
            rz = hn::Neg(depth);
        }
    }
    if (!need_cos) {
        m.cos_e = hn::Zero(df);
        return m;
    }
    const VF n2 = hn::MulAdd(rx, rx, hn::MulAdd(ry, ry, hn::Mul(rz, rz)));
    const VF dot =
        hn::MulAdd(hn::Set(df, p.gaze[0]), rx,
                   hn::MulAdd(hn::Set(df, p.gaze[1]), ry, hn::Mul(hn::Set(df, p.gaze[2]), rz)));
    m.cos_e = hn::Div(dot, hn::Sqrt(n2));
    return m;
}

// Byte c of every RGBA8 texel as the float kTexelBias + c (docs/UCA.md, "Biased channels"):
// the byte lands in bits 8–15 of a float whose exponent is 2^15, so one byte shuffle (masked
// into a constant on AVX-512) replaces a shuffle and an int → float conversion.
template <int kChannel>
HWY_INLINE VF channel(VU texel) {
    const DF df;
    const DU du;
#if HWY_TARGET == HWY_SCALAR
    return hn::BitCast(
        df,
        hn::Or(hn::ShiftLeft<8>(hn::And(hn::ShiftRight<8 * kChannel>(texel), hn::Set(du, 0xFFu))),
               hn::Set(du, kTexelBiasBits)));
#else
    const hn::Repartition<uint8_t, DU> d8;
    // Shuffle indices are byte positions within each 16-byte block: lane j of a block holds its
    // texel in bytes 4j…4j+3; byte 1 of lane j takes byte 4j + c, the others stay zero.
    const VU lane_in_block = hn::And(hn::Iota(du, 0u), hn::Set(du, 3u));
    const VU index = hn::Add(hn::ShiftLeft<10>(lane_in_block),
                             hn::Set(du, 0x80800080u | (static_cast<uint32_t>(kChannel) << 8)));
    const auto pick = hn::BitCast(d8, index);
#if HWY_TARGET <= HWY_AVX3
    (void)d8;
    if constexpr (kChannel == 1) {
        // Green is already in bits 8–15: one bit select (any vector port) instead of a shuffle
        // (port 5 only, which the permutes and shuffles already keep busy).
        return hn::BitCast(df,
                           VU{_mm512_ternarylogic_epi32(texel.raw, hn::Set(du, 0xFF00u).raw,
                                                        hn::Set(du, kTexelBiasBits).raw, 0xEA)});
    }
    return hn::BitCast(
        df, VU{_mm512_mask_shuffle_epi8(hn::Set(du, kTexelBiasBits).raw, 0x2222222222222222ull,
                                        texel.raw, pick.raw)});
#else
    const auto bytes = hn::TableLookupBytesOr0(hn::BitCast(d8, texel), pick);
    return hn::BitCast(df, hn::Or(hn::BitCast(du, bytes), hn::Set(du, kTexelBiasBits)));
#endif
#endif
}

HWY_INLINE VF lerp(VF w, VF a, VF b) {
    return hn::MulAdd(w, hn::Sub(b, a), a);
}

// The four taps of every lane: t00 at (flx, fly), t10 one texel right, t01 one below, t11 both.
struct Taps {
    VU t00, t10, t01, t11;
};

#if HWY_TARGET != HWY_SCALAR
// Taps by gathers, for 0 ≤ flx ≤ width − 2 and 0 ≤ fly ≤ height − 2. The two taps of a row are
// neighbours in memory: fetch them as one 64-bit element, half the gathered elements.
HWY_INLINE Taps gatherTaps(const KernelLayer& l, VF flx, VF fly) {
    const DF df;
    const DU du;
    // Texel index in float is exact: layers hold fewer than 2^24 texels (validateFrame).
    const VI i00 = truncToInt(hn::MulAdd(fly, hn::Set(df, static_cast<float>(l.width)), flx));
    VU r0_lo, r0_hi, r1_lo, r1_hi;
#if HWY_TARGET <= HWY_AVX3
    // 32-bit texel indices scaled by 4 bytes in the gather itself: no widening, no shifts.
    const DI di;
    const VI i01 = hn::Add(i00, hn::Set(di, l.width));
    const __m256i i00_hi = _mm512_extracti64x4_epi64(i00.raw, 1);
    const __m256i i01_hi = _mm512_extracti64x4_epi64(i01.raw, 1);
    r0_lo = VU{_mm512_i32gather_epi64(_mm512_castsi512_si256(i00.raw), l.texels, 4)};
    r0_hi = VU{_mm512_i32gather_epi64(i00_hi, l.texels, 4)};
    r1_lo = VU{_mm512_i32gather_epi64(_mm512_castsi512_si256(i01.raw), l.texels, 4)};
    r1_hi = VU{_mm512_i32gather_epi64(i01_hi, l.texels, 4)};
#else
    const hn::Half<DI> dh;
    const hn::Repartition<uint64_t, DU> d64;
    const hn::RebindToSigned<decltype(d64)> di64;
    const auto* base64 = reinterpret_cast<const uint64_t*>(l.texels);
    const auto lo = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::LowerHalf(dh, i00)));
    const auto hi = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::UpperHalf(dh, i00)));
    const auto row_bytes = hn::Set(di64, int64_t{4} * l.width);
    r0_lo = hn::BitCast(du, hn::GatherOffset(d64, base64, lo));
    r0_hi = hn::BitCast(du, hn::GatherOffset(d64, base64, hi));
    r1_lo = hn::BitCast(du, hn::GatherOffset(d64, base64, hn::Add(lo, row_bytes)));
    r1_hi = hn::BitCast(du, hn::GatherOffset(d64, base64, hn::Add(hi, row_bytes)));
#endif
    return {hn::ConcatEven(du, r0_hi, r0_lo), hn::ConcatOdd(du, r0_hi, r0_lo),
            hn::ConcatEven(du, r1_hi, r1_lo), hn::ConcatOdd(du, r1_hi, r1_lo)};
}
#endif

#if HWY_TARGET <= HWY_AVX3
// Taps by whole-row loads and two-table permutes where the lanes' footprint is small (docs/UCA.md,
// "Row windows"); false leaves them to the gathers. Same texels, so the same result. Mesh tiles
// only: their taps lie inside the layer, so every window starts and ends inside it.
//  * Narrow: every left tap within 14 texels of lane 0's and every top tap in row y or y + 1,
//    y = min(lane 0's row, lane 15's): rows y, y + 1, y + 2 as 16 texels each; bit 4 of a
//    permute index picks the lower of two rows, so a lane's own row costs nothing.
//  * Wide: every top tap in lane 0's row, left taps within 30 texels: two rows of 32 texels.
// The four taps from two 32-texel tables, top = (top_lo, top_hi) and bottom = (bot_lo, bot_hi):
// left taps at index i, right taps at i + 1.
HWY_INLINE Taps permuteFour(__m512i top_lo, __m512i top_hi, __m512i bot_lo, __m512i bot_hi,
                            __m512i i) {
    const __m512i i1 = _mm512_add_epi32(i, _mm512_set1_epi32(1));
    return {VU{_mm512_permutex2var_epi32(top_lo, i, top_hi)},
            VU{_mm512_permutex2var_epi32(top_lo, i1, top_hi)},
            VU{_mm512_permutex2var_epi32(bot_lo, i, bot_hi)},
            VU{_mm512_permutex2var_epi32(bot_lo, i1, bot_hi)}};
}

HWY_INLINE bool permuteTaps(const KernelLayer& l, VF flx, VF fly, Taps& taps) {
    const VI ix = truncToInt(flx);
    const VI iy = truncToInt(fly);
    const int x0 = _mm_cvtsi128_si32(_mm512_castsi512_si128(ix.raw));
    const int y0 = _mm_cvtsi128_si32(_mm512_castsi512_si128(iy.raw));
    const int y15 =
        _mm_cvtsi128_si32(_mm512_castsi512_si128(_mm512_alignr_epi32(iy.raw, iy.raw, 15)));
    const int y = y0 < y15 ? y0 : y15;
    const __m512i rel = _mm512_sub_epi32(ix.raw, _mm512_set1_epi32(x0));
    const __m512i dy = _mm512_sub_epi32(iy.raw, _mm512_set1_epi32(y));
    const __m512i one = _mm512_set1_epi32(1);
    const auto* base = reinterpret_cast<const uint32_t*>(l.texels);
    const __mmask16 narrow =
        _mm512_mask_cmple_epu32_mask(_mm512_cmple_epu32_mask(dy, one), rel, _mm512_set1_epi32(14));
    if (narrow == 0xFFFF && x0 + 16 <= l.width && y + 2 < l.height) {
        const uint32_t* row = base + static_cast<size_t>(y) * static_cast<size_t>(l.width) + x0;
        const __m512i r0 = _mm512_loadu_si512(row);
        const __m512i r1 = _mm512_loadu_si512(row + l.width);
        const __m512i r2 = _mm512_loadu_si512(row + 2 * static_cast<size_t>(l.width));
        // Top taps from rows y / y + 1, bottom taps from y + 1 / y + 2, the row by index bit 4.
        taps = permuteFour(r0, r1, r1, r2, _mm512_or_si512(rel, _mm512_slli_epi32(dy, 4)));
        return true;
    }
    const __mmask16 wide = _mm512_mask_cmple_epu32_mask(
        _mm512_cmpeq_epi32_mask(iy.raw, _mm512_set1_epi32(y0)), rel, _mm512_set1_epi32(30));
    if (wide == 0xFFFF && x0 + 32 <= l.width) {
        const uint32_t* row0 = base + static_cast<size_t>(y0) * static_cast<size_t>(l.width) + x0;
        const uint32_t* row1 = row0 + l.width;
        taps = permuteFour(_mm512_loadu_si512(row0), _mm512_loadu_si512(row0 + 16),
                           _mm512_loadu_si512(row1), _mm512_loadu_si512(row1 + 16), rel);
        return true;
    }
    return false;
}
#endif

// Bilinear RGB of one layer at texel coordinates (lx, ly). kClamp: clamp to the edge. Without
// it the caller guarantees 0 ≤ lx < width − 1 and 0 ≤ ly < height − 1 (mesh tiles), where the
// clamps below change nothing.
template <bool kClamp>
HWY_INLINE Rgb sampleTexels(const KernelLayer& l, VF lx, VF ly) {
    const DF df;
    const DI di;
    const DU du;
    // Clamping the texel coordinate to [0, size − 1] is clamp-to-edge: at the edge the weight
    // of the tap beyond it is 0, and that tap is redirected onto the edge texel.
    const VF max_x = hn::Set(df, static_cast<float>(l.width - 1));
    const VF max_y = hn::Set(df, static_cast<float>(l.height - 1));
    if (kClamp) {
        const VF zero = hn::Zero(df);
        lx = hn::Min(hn::Max(lx, zero), max_x);
        ly = hn::Min(hn::Max(ly, zero), max_y);
    }
    VF flx = hn::Floor(lx);
    VF fly = hn::Floor(ly);
    Taps taps;
#if HWY_TARGET != HWY_SCALAR
    if (l.width >= 2 && l.height >= 2) {
        // The left tap stops one short of the edge, where the weight of the right tap becomes
        // exactly 1, so no fetch passes the end of a row.
        if (kClamp) {
            flx = hn::Min(flx, hn::Sub(max_x, hn::Set(df, 1.0f)));
            fly = hn::Min(fly, hn::Sub(max_y, hn::Set(df, 1.0f)));
        }
#if HWY_TARGET <= HWY_AVX3
        if (kClamp || !permuteTaps(l, flx, fly, taps))
            taps = gatherTaps(l, flx, fly);
#else
        taps = gatherTaps(l, flx, fly);
#endif
    } else
#endif
    {
        const auto* base = reinterpret_cast<const uint32_t*>(l.texels);
        const VI i00 =
            hn::ConvertTo(di, hn::MulAdd(fly, hn::Set(df, static_cast<float>(l.width)), flx));
        const VI step_x =
            hn::IfThenElseZero(hn::RebindMask(di, hn::Lt(flx, max_x)), hn::Set(di, 1));
        const VI step_y =
            hn::IfThenElseZero(hn::RebindMask(di, hn::Lt(fly, max_y)), hn::Set(di, l.width));
        const VI i01 = hn::Add(i00, step_y);
        taps.t00 = hn::GatherIndex(du, base, i00);
        taps.t10 = hn::GatherIndex(du, base, hn::Add(i00, step_x));
        taps.t01 = hn::GatherIndex(du, base, i01);
        taps.t11 = hn::GatherIndex(du, base, hn::Add(i01, step_x));
    }
    const VF wx = hn::Sub(lx, flx);
    const VF wy = hn::Sub(ly, fly);
    Rgb out;
    const Taps& t = taps;
    out.r = lerp(wy, lerp(wx, channel<0>(t.t00), channel<0>(t.t10)),
                 lerp(wx, channel<0>(t.t01), channel<0>(t.t11)));
    out.g = lerp(wy, lerp(wx, channel<1>(t.t00), channel<1>(t.t10)),
                 lerp(wx, channel<1>(t.t01), channel<1>(t.t11)));
    out.b = lerp(wy, lerp(wx, channel<2>(t.t00), channel<2>(t.t10)),
                 lerp(wx, channel<2>(t.t01), channel<2>(t.t11)));
    return out;
}

HWY_INLINE Rgb sampleLayer(const KernelLayer& l, VF px, VF py) {
    const DF df;
    return sampleTexels<true>(l, hn::MulAdd(px, hn::Set(df, l.inv_scale), hn::Set(df, l.offset_x)),
                              hn::MulAdd(py, hn::Set(df, l.inv_scale), hn::Set(df, l.offset_y)));
}

// Biased channels → values (exact: both lie on the same 1/256 grid within a factor of 2).
HWY_INLINE Rgb unbias(const Rgb& c) {
    const DF df;
    const VF bias = hn::Set(df, kTexelBias);
    return {hn::Sub(c.r, bias), hn::Sub(c.g, bias), hn::Sub(c.b, bias)};
}

// Eq. 4's blend of the slots in slot_mask at rendered-image points with eccentricity cosines
// cos_e (unbiased values).
HWY_INLINE Rgb blendSlots(const KernelParams& p, uint8_t slot_mask, VF px, VF py, VF cos_e) {
    const DF df;
    const VF zero = hn::Zero(df);
    const VF one = hn::Set(df, 1.0f);
    const VF t1 = hn::Min(hn::Max(hn::Mul(hn::Sub(hn::Set(df, p.border_c_hi[0]), cos_e),
                                          hn::Set(df, p.border_inv[0])),
                                  zero),
                          one);
    const VF t2 = hn::Min(hn::Max(hn::Mul(hn::Sub(hn::Set(df, p.border_c_hi[1]), cos_e),
                                          hn::Set(df, p.border_inv[1])),
                                  zero),
                          one);
    const VF t12 = hn::Mul(t1, t2);
    const VF w[3] = {hn::Sub(one, t1), hn::Sub(t1, t12), t12};
    Rgb rgb = {zero, zero, zero};
    for (int k = 0; k < p.slot_count; ++k) {
        if ((slot_mask & (1u << k)) == 0)
            continue;
        // Lanes outside this layer's ramp have weight 0; skip the gathers when all do.
        if (hn::AllFalse(df, hn::Gt(w[k], zero)))
            continue;
        const Rgb s = unbias(sampleLayer(p.slots[k], px, py));
        rgb.r = hn::MulAdd(w[k], s.r, rgb.r);
        rgb.g = hn::MulAdd(w[k], s.g, rgb.g);
        rgb.b = hn::MulAdd(w[k], s.b, rgb.b);
    }
    return rgb;
}

// Eq. 4 for a vector of pixels; lanes off the rendered image come back in `valid`.
HWY_INLINE Rgb shade(const KernelParams& p, const RowMap& r, VF u, VF v, float chroma,
                     uint8_t slot_mask, MF& valid) {
    const bool single = (slot_mask & (slot_mask - 1)) == 0;
    const MapV m = mapPixels(p, r, u, v, chroma, !single);
    Rgb rgb;
    if (single) {
        const int k = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        rgb = unbias(sampleLayer(p.slots[k], m.px, m.py));
    } else {
        rgb = blendSlots(p, slot_mask, m.px, m.py, m.cos_e);
    }
    valid = m.valid;
    return rgb;
}

HWY_INLINE VU quantize(VF value) {
    const DF df;
    const DI di;
    const DU du;
    // A convex combination of bytes stays within [0, 255], so +0.5 and truncation round it.
    (void)di;
    return hn::BitCast(du, truncToInt(hn::Add(value, hn::Set(df, 0.5f))));
}

HWY_INLINE VU pack(VF r, VF g, VF b) {
    const DU du;
    VU packed = hn::Or(quantize(r), hn::ShiftLeft<8>(quantize(g)));
    packed = hn::Or(packed, hn::ShiftLeft<16>(quantize(b)));
    return hn::Or(packed, hn::Set(du, kOpaqueBlack));
}

// RGBA8 of biased channels (each kTexelBias + value, value in [0, 255]): bits 8–15 of each are
// the rounded byte, as quantize() gives for unbiased values.
HWY_INLINE VU packBiased(const Rgb& c) {
    const DU du;
    const VU r = hn::BitCast(du, c.r);
    const VU g = hn::BitCast(du, c.g);
    const VU b = hn::BitCast(du, c.b);
    // (r >> 8) holds the red byte in bits 0–7; g its green byte in bits 8–15; (b << 8) its blue
    // byte in bits 16–23 and zeros above.
    // Bit selects written out: Highway's IfVecThenElse wants whole-lane masks (its SCALAR target
    // selects whole lanes); on x86 each of these becomes one vpternlogd.
    const VU low8 = hn::Set(du, 0xFFu);
    const VU low16 = hn::Set(du, 0xFFFFu);
    const VU rg = hn::Or(hn::And(low8, hn::ShiftRight<8>(r)), hn::AndNot(low8, g));
    const VU rgb = hn::Or(hn::And(low16, rg), hn::AndNot(low16, hn::ShiftLeft<8>(b)));
    return hn::Or(rgb, hn::Set(du, kOpaqueBlack));
}

HWY_INLINE VU shadePacked(const KernelParams& p, const RowMap& r, VF u, VF v, uint8_t slot_mask) {
    const DU du;
    MF valid;
    if (!p.chroma && (slot_mask & (slot_mask - 1)) == 0) {
        // One layer: its biased channels go straight to bytes.
        const MapV m = mapPixels(p, r, u, v, 1.0f, false);
        // Tiles at the rendered image's edge have whole vectors off it: no samples there.
        if (hn::AllFalse(hn::DFromV<VF>(), m.valid))
            return hn::Set(du, kOpaqueBlack);
        const int k = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        return hn::IfThenElse(hn::RebindMask(du, m.valid),
                              packBiased(sampleLayer(p.slots[k], m.px, m.py)),
                              hn::Set(du, kOpaqueBlack));
    }
    if (!p.chroma) {
        const Rgb c = shade(p, r, u, v, 1.0f, slot_mask, valid);
        // Off-image lanes become opaque black once, after packing.
        return hn::IfThenElse(hn::RebindMask(du, valid), pack(c.r, c.g, c.b),
                              hn::Set(du, kOpaqueBlack));
    }
    // Lateral chromatic aberration: each channel has its own map and its own validity.
    const VF red = shade(p, r, u, v, p.chroma_red, slot_mask, valid).r;
    const VF rv = hn::IfThenElseZero(valid, red);
    const VF green = shade(p, r, u, v, 1.0f, slot_mask, valid).g;
    const VF gv = hn::IfThenElseZero(valid, green);
    const VF blue = shade(p, r, u, v, p.chroma_blue, slot_mask, valid).b;
    const VF bv = hn::IfThenElseZero(valid, blue);
    return pack(rv, gv, bv);
}

// The exact map (steps 1–4) at the tile's 9×9 lattice (docs/UCA.md, "Mesh tiles"), a vector
// of lattice points at a time, with the texel coordinate in `layer` (single-layer plan). Each
// lane has its own row, so the row constants of rowMap() are formed
// per lane with the same float operations.
HWY_INLINE void mapLattice(const KernelParams& p, const TileJob& job, const MeshPlan& plan,
                           MeshLattice& out) {
    const DF df;
    const int lanes = static_cast<int>(hn::Lanes(df));
    HWY_ALIGN static const auto offsets = [] {
        struct {
            float u[kMeshLatticeStorage], v[kMeshLatticeStorage];
        } o{};
        for (int k = 0; k < kMeshLatticeStorage; ++k) {
            const int i = k < kMeshLatticePoints ? k % kMeshLatticeSide : 0;
            const int j = k < kMeshLatticePoints ? k / kMeshLatticeSide : 0;
            o.u[k] = static_cast<float>(i * (kMeshStepPx / 2));
            o.v[k] = static_cast<float>(j * (kMeshStepPx / 2));
        }
        return o;
    }();
    const KernelLayer& layer = p.slots[plan.layer];
    const RowMap r0 = rowMap(p, 0.0f);
    const VF x0 = hn::Set(df, static_cast<float>(job.x0));
    const VF y0 = hn::Set(df, static_cast<float>(job.y0));
    const VF zero = hn::Zero(df);
    for (int k = 0; k < 16; k += lanes) {
        hn::StoreU(zero, df, out.head + k);
        hn::StoreU(zero, df, out.tail + k);
    }
    for (int k = 0; k < kMeshLatticeStorage; k += lanes) {
        const VF u = hn::Add(x0, hn::Load(df, offsets.u + k));
        const VF v = hn::Add(y0, hn::Load(df, offsets.v + k));
        const VF yt = hn::Add(hn::Mul(v, hn::Set(df, p.ay)), hn::Set(df, p.by));
        const VF yt2 = hn::Mul(yt, yt);
        const VF cx_row = hn::Mul(hn::Set(df, p.fx * p.m[1]), yt);
        const VF cy_row = hn::Mul(hn::Set(df, -p.fy * p.m[4]), yt);
        const VF cz_row = hn::Mul(hn::Set(df, p.m[7]), yt);
        const VF xt = hn::MulAdd(u, hn::Set(df, p.ax), hn::Set(df, p.bx));
        const VF r2 = hn::MulAdd(xt, xt, yt2);
        const VF poly = hn::MulAdd(hn::Set(df, p.k2), r2, hn::Set(df, p.k1));
        const VF f = hn::MulAdd(poly, r2, hn::Set(df, 1.0f));
        const VF num_x =
            hn::MulAdd(f, hn::MulAdd(xt, hn::Set(df, r0.mx), cx_row), hn::Set(df, -r0.ox));
        const VF num_y =
            hn::MulAdd(f, hn::MulAdd(xt, hn::Set(df, r0.my), cy_row), hn::Set(df, -r0.oy));
        const VF depth =
            hn::NegMulAdd(f, hn::MulAdd(xt, hn::Set(df, r0.mz), cz_row), hn::Set(df, r0.dz));
        const MF front = hn::Gt(depth, hn::Set(df, 1e-6f));
        const VF iz = hn::Div(hn::Set(df, 1.0f), hn::IfThenElse(front, depth, hn::Set(df, 1.0f)));
        const VF px = hn::MulAdd(num_x, iz, hn::Set(df, p.cx));
        const VF py = hn::MulAdd(num_y, iz, hn::Set(df, p.cy));
        const MF in_x = hn::And(hn::Ge(px, zero), hn::Le(px, hn::Set(df, p.width)));
        const MF in_y = hn::And(hn::Ge(py, zero), hn::Le(py, hn::Set(df, p.height)));
        const MF valid = hn::And(front, hn::And(in_x, in_y));
        const VF vx = hn::IfThenElseZero(valid, px);
        const VF vy = hn::IfThenElseZero(valid, py);
        hn::Store(vx, df, out.px + k);
        hn::Store(vy, df, out.py + k);
        if (!plan.border) {
            hn::Store(hn::MulAdd(vx, hn::Set(df, layer.inv_scale), hn::Set(df, layer.offset_x)), df,
                      out.lx + k);
            hn::Store(hn::MulAdd(vy, hn::Set(df, layer.inv_scale), hn::Set(df, layer.offset_y)), df,
                      out.ly + k);
        }
    }
}

// cos e of rendered-image points: the direction ((px − cx)/fx, −(py − cy)/fy, −1) against the
// gaze (border mesh tiles; the same operations as the twin's meshEccentricityCos).
HWY_INLINE VF eccentricityCos(const KernelParams& p, VF px, VF py) {
    const DF df;
    const VF rx = hn::Mul(hn::Sub(px, hn::Set(df, p.cx)), hn::Set(df, 1.0f / p.fx));
    const VF ry = hn::Mul(hn::Sub(hn::Set(df, p.cy), py), hn::Set(df, 1.0f / p.fy));
    const VF n2 = hn::MulAdd(rx, rx, hn::MulAdd(ry, ry, hn::Set(df, 1.0f)));
    const VF dot = hn::MulAdd(hn::Set(df, p.gaze[0]), rx,
                              hn::MulAdd(hn::Set(df, p.gaze[1]), ry, hn::Set(df, -p.gaze[2])));
    return hn::Div(dot, hn::Sqrt(n2));
}

// meshAcceptable() a vector of lattice points at a time: the same comparisons on the same
// floats (each midpoint's interpolation is formed exactly as there), lanes selected by the
// point's kind — node, horizontal or vertical edge midpoint, cell centre.
HWY_INLINE bool meshAcceptableV(const MeshLattice& m, const KernelParams& p, const MeshPlan& plan) {
    const DF df;
    const DU du;
    const int lanes = static_cast<int>(hn::Lanes(df));
    HWY_ALIGN static const auto kinds = [] {
        struct {
            uint32_t point[kMeshLatticeStorage], h[kMeshLatticeStorage], v[kMeshLatticeStorage],
                c[kMeshLatticeStorage];
        } t{};
        for (int k = 0; k < kMeshLatticePoints; ++k) {
            const int i = k % kMeshLatticeSide, j = k / kMeshLatticeSide;
            t.point[k] = ~0u;
            t.h[k] = (i & 1) != 0 && (j & 1) == 0 ? ~0u : 0u;
            t.v[k] = (i & 1) == 0 && (j & 1) != 0 ? ~0u : 0u;
            t.c[k] = (i & 1) != 0 && (j & 1) != 0 ? ~0u : 0u;
        }
        return t;
    }();
    constexpr int n = kMeshLatticeSide;
    const KernelLayer& l = p.slots[plan.layer];
    const VF margin = hn::Set(df, kMeshMarginPx);
    const VF max_px = hn::Set(df, p.width - kMeshMarginPx);
    const VF max_py = hn::Set(df, p.height - kMeshMarginPx);
    const VF tmargin = hn::Set(df, kMeshTexelMargin);
    const VF max_lx = hn::Set(df, static_cast<float>(l.width - 1) - kMeshTexelMargin);
    const VF max_ly = hn::Set(df, static_cast<float>(l.height - 1) - kMeshTexelMargin);
    const VF half = hn::Set(df, 0.5f);
    const VF quarter = hn::Set(df, 0.25f);
    const float* xs = plan.border ? m.px : m.lx;
    const float* ys = plan.border ? m.py : m.ly;
    // Lanes of each midpoint kind whose error exceeds the bound, for one coordinate.
    auto bad = [&](const float* v, int k, float bound_f, VU h, VU vert, VU c) {
        const VF bound = hn::Set(df, bound_f);
        const VF neg_bound = hn::Set(df, -bound_f);
        auto within = [&](VF err) { return hn::And(hn::Le(err, bound), hn::Ge(err, neg_bound)); };
        const VF x = hn::Load(df, v + k);
        const VF eh =
            hn::Sub(x, hn::Mul(half, hn::Add(hn::LoadU(df, v + k - 1), hn::LoadU(df, v + k + 1))));
        const VF ev =
            hn::Sub(x, hn::Mul(half, hn::Add(hn::LoadU(df, v + k - n), hn::LoadU(df, v + k + n))));
        const VF ec = hn::Sub(
            x,
            hn::Mul(quarter,
                    hn::Add(hn::Add(hn::LoadU(df, v + k - n - 1), hn::LoadU(df, v + k - n + 1)),
                            hn::Add(hn::LoadU(df, v + k + n - 1), hn::LoadU(df, v + k + n + 1)))));
        const auto fh = hn::AndNot(hn::RebindMask(du, within(eh)), hn::MaskFromVec(h));
        const auto fv = hn::AndNot(hn::RebindMask(du, within(ev)), hn::MaskFromVec(vert));
        const auto fc = hn::AndNot(hn::RebindMask(du, within(ec)), hn::MaskFromVec(c));
        return hn::Or(fh, hn::Or(fv, fc));
    };
    for (int k = 0; k < kMeshLatticeStorage; k += lanes) {
        const VF px = hn::Load(df, m.px + k), py = hn::Load(df, m.py + k);
        auto inside = hn::And(hn::And(hn::Ge(px, margin), hn::Le(px, max_px)),
                              hn::And(hn::Ge(py, margin), hn::Le(py, max_py)));
        if (!plan.border) {
            const VF lx = hn::Load(df, m.lx + k), ly = hn::Load(df, m.ly + k);
            inside = hn::And(inside, hn::And(hn::And(hn::Ge(lx, tmargin), hn::Le(lx, max_lx)),
                                             hn::And(hn::Ge(ly, tmargin), hn::Le(ly, max_ly))));
        }
        const VU point = hn::Load(du, kinds.point + k);
        const VU h = hn::Load(du, kinds.h + k), vert = hn::Load(du, kinds.v + k),
                 c = hn::Load(du, kinds.c + k);
        auto fail = hn::AndNot(hn::RebindMask(du, inside), hn::MaskFromVec(point));
        fail = hn::Or(fail, hn::Or(bad(xs, k, plan.bound_xy, h, vert, c),
                                   bad(ys, k, plan.bound_xy, h, vert, c)));
        if (!hn::AllFalse(du, fail))
            return false;
    }
    return true;
}

// Stores a vector of packed pixels at row[x…]: streaming where aligned and the job asks for it,
// a partial store at the tile's right edge.
HWY_INLINE void storePixels(hn::Vec<hn::ScalableTag<uint32_t>> packed, const TileJob& job,
                            uint32_t* row, int x) {
    const hn::ScalableTag<uint32_t> du;
    const int lanes = static_cast<int>(hn::Lanes(du));
    const uintptr_t vector_bytes = static_cast<uintptr_t>(lanes) * sizeof(uint32_t);
    if (x + lanes <= job.x1) {
        if (job.stream && (reinterpret_cast<uintptr_t>(row + x) & (vector_bytes - 1)) == 0)
            hn::Stream(packed, du, row + x);
        else
            hn::StoreU(packed, du, row + x);
        return;
    }
    HWY_ALIGN uint32_t tail[HWY_MAX_BYTES / sizeof(uint32_t)];
    hn::Store(packed, du, tail);
    std::memcpy(row + x, tail, static_cast<size_t>(job.x1 - x) * sizeof(uint32_t));
}

// A mesh tile: the interpolated values of every pixel are the bilinear interpolation of the
// lattice's nodes, first along x on the node rows (h), then along y between them; every pixel
// is valid. Single-layer tiles interpolate texel coordinates and sample without clamps; border
// tiles interpolate the rendered-image point and blend (Eq. 4) by its eccentricity.
template <bool kBorder>
HWY_INLINE void meshTile(const KernelParams& p, const TileJob& job, const MeshLattice& m,
                         const MeshPlan& plan) {
    const DF df;
    const int lanes = static_cast<int>(hn::Lanes(df));
    constexpr int n = kMeshLatticeSide;
    constexpr int kCoords = 2;
    HWY_ALIGN static const auto frac = [] {
        struct {
            float a[kTilePx];
        } f{};
        for (int c = 0; c < kTilePx; ++c)
            f.a[c] = static_cast<float>(c % kMeshStepPx) * (1.0f / kMeshStepPx);
        return f;
    }();
    const float* src[2] = {kBorder ? m.px : m.lx, kBorder ? m.py : m.ly};
    HWY_ALIGN float h[kCoords][kMeshCells + 1][kTilePx];
    HWY_ALIGN float d[kCoords][kMeshCells][kTilePx];
    const MF upper = hn::Ge(hn::Iota(df, 0.0f), hn::Set(df, static_cast<float>(kMeshStepPx)));
    // The node of column c's cell (offset 0) or the next (offset 1), per lane.
    auto node = [&](const float* lattice_row, int c, int offset) {
        const int cell = c / kMeshStepPx + offset;
        const VF here = hn::Set(df, lattice_row[2 * cell]);
        if (lanes <= kMeshStepPx)
            return here;
        return hn::IfThenElse(upper, hn::Set(df, lattice_row[2 * cell + 2]), here);
    };
    for (int q = 0; q < kCoords; ++q) {
        for (int j = 0; j <= kMeshCells; ++j) {
            const float* row = src[q] + 2 * j * n;
            for (int c = 0; c < kTilePx; c += lanes) {
                const VF a = hn::Load(df, frac.a + c);
                const VF left = node(row, c, 0);
                hn::Store(hn::MulAdd(hn::Sub(node(row, c, 1), left), a, left), df, h[q][j] + c);
            }
        }
        for (int j = 0; j < kMeshCells; ++j) {
            for (int c = 0; c < kTilePx; c += lanes) {
                hn::Store(hn::Sub(hn::Load(df, h[q][j + 1] + c), hn::Load(df, h[q][j] + c)), df,
                          d[q][j] + c);
            }
        }
    }
    for (int y = job.y0; y < job.y1; ++y) {
        auto* row =
            reinterpret_cast<uint32_t*>(job.out) + static_cast<size_t>(y) * job.out_stride_px;
        const int j = (y - job.y0) / kMeshStepPx;
        const VF b =
            hn::Set(df, static_cast<float>((y - job.y0) % kMeshStepPx) * (1.0f / kMeshStepPx));
        for (int x = job.x0; x < job.x1; x += lanes) {
            const int c = x - job.x0;
            const VF vx = hn::MulAdd(hn::Load(df, d[0][j] + c), b, hn::Load(df, h[0][j] + c));
            const VF vy = hn::MulAdd(hn::Load(df, d[1][j] + c), b, hn::Load(df, h[1][j] + c));
            VU packed;
            if constexpr (kBorder) {
                const Rgb rgb = blendSlots(p, job.slot_mask, vx, vy, eccentricityCos(p, vx, vy));
                packed = pack(rgb.r, rgb.g, rgb.b);
            } else {
                packed = packBiased(sampleTexels<false>(p.slots[plan.layer], vx, vy));
            }
            storePixels(packed, job, row, x);
        }
    }
}

}  // namespace

bool UcaTile(const KernelParams& p, const TileJob& job) {
    if (job.mesh && job.slot_mask != 0 && !p.identity_map && !p.chroma &&
        job.x1 - job.x0 <= kTilePx && job.y1 - job.y0 <= kTilePx) {
        const MeshPlan plan = meshPlan(p, job.slot_mask);
        HWY_ALIGN MeshLattice lattice;
        if (plan.usable) {
            mapLattice(p, job, plan, lattice);
            if (meshAcceptableV(lattice, p, plan)) {
                if (plan.border) {
                    meshTile<true>(p, job, lattice, plan);
                } else {
                    meshTile<false>(p, job, lattice, plan);
                }
                return true;
            }
        }
    }
    const DF df;
    const DU du;
    const int lanes = static_cast<int>(hn::Lanes(df));
    const VF iota = hn::Iota(df, 0.0f);
    for (int y = job.y0; y < job.y1; ++y) {
        auto* row =
            reinterpret_cast<uint32_t*>(job.out) + static_cast<size_t>(y) * job.out_stride_px;
        const VF v = hn::Set(df, static_cast<float>(y));
        const RowMap r = rowMap(p, static_cast<float>(y));
        for (int x = job.x0; x < job.x1; x += lanes) {
            VU packed;
            if (job.slot_mask == 0) {
                packed = hn::Set(du, kOpaqueBlack);
            } else {
                const VF u = hn::Add(iota, hn::Set(df, static_cast<float>(x)));
                packed = shadePacked(p, r, u, v, job.slot_mask);
            }
            storePixels(packed, job, row, x);
        }
    }
    return false;
}

const char* TargetName() {
    return hwy::TargetName(HWY_TARGET);
}

}  // namespace HWY_NAMESPACE
}  // namespace qvr::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace qvr::detail {
HWY_EXPORT(UcaTile);
HWY_EXPORT(TargetName);

const char* ucaSimdTarget() {
    return HWY_DYNAMIC_DISPATCH(TargetName)();
}

void ucaFenceStreams() {
    hwy::FlushStream();
}

bool ucaTileSimd(const KernelParams& p, const TileJob& job) {
    return HWY_DYNAMIC_DISPATCH(UcaTile)(p, job);
}

std::vector<int64_t> ucaAvailableTargets() {
    return hwy::SupportedAndGeneratedTargets();
}

const char* ucaTargetName(int64_t target) {
    return hwy::TargetName(target);
}

void ucaSetTargetsForTest(int64_t targets) {
    hwy::SetSupportedTargetsForTest(targets);
}
}  // namespace qvr::detail
#endif
