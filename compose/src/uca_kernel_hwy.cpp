// The vectorised UCA tile kernel (paper §4.2, Eq. 4) with Highway: a vector of display pixels is
// mapped through lens and rotation at once, each layer's taps come from contiguous row loads and
// lane permutes (gathers where the taps are scattered), and the bilinear filter and Eq. 4's
// blend run in 16-bit fixed point.
// Dispatches to the best target the CPU has at run time; docs/UCA.md describes every step.
#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "uca_kernel_hwy.cpp"
#include <hwy/cache_control.h>
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "uca_kernel.h"

// GCC 12 flags the self-initialised _mm512_undefined_epi32() inside the AVX-512 permute
// intrinsics as maybe-uninitialized (a known false positive of the compiler's own headers).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

HWY_BEFORE_NAMESPACE();
namespace qvr::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#undef QVR_UCA_VECTOR
#undef QVR_UCA_ROW_LOADS
#if HWY_ARCH_X86 && HWY_TARGET != HWY_SCALAR && HWY_TARGET != HWY_EMU128
#define QVR_UCA_VECTOR 1
#else
#define QVR_UCA_VECTOR 0
#endif

#if QVR_UCA_VECTOR
namespace {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using D16 = hn::Repartition<int16_t, DF>;
using DU16 = hn::Repartition<uint16_t, DF>;
using D8 = hn::Repartition<uint8_t, DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using V16 = hn::Vec<D16>;
using V8 = hn::Vec<D8>;
using MF = hn::Mask<DF>;

#if HWY_TARGET <= HWY_AVX3
#define QVR_UCA_ROW_LOADS 1
#else
#define QVR_UCA_ROW_LOADS 0
#endif

// The few x86 instructions Highway 1.0.3 does not name, at every width of the block-wise ops:
// u8 × i8 pairs summed into i16 (pmaddubsw), and i16 → u8 saturating pack within each 16-byte
// block (packuswb), which undoes the block-wise interleave that built the pairs.
HWY_INLINE V16 mulPairs(V8 texel_pairs, V8 weight_pairs) {
#if HWY_TARGET <= HWY_AVX3
    return V16{_mm512_maddubs_epi16(texel_pairs.raw, weight_pairs.raw)};
#elif HWY_TARGET == HWY_AVX2
    return V16{_mm256_maddubs_epi16(texel_pairs.raw, weight_pairs.raw)};
#else
    return V16{_mm_maddubs_epi16(texel_pairs.raw, weight_pairs.raw)};
#endif
}

HWY_INLINE V8 packBlocks(V16 lo, V16 hi) {
#if HWY_TARGET <= HWY_AVX3
    return V8{_mm512_packus_epi16(lo.raw, hi.raw)};
#elif HWY_TARGET == HWY_AVX2
    return V8{_mm256_packus_epi16(lo.raw, hi.raw)};
#else
    return V8{_mm_packus_epi16(lo.raw, hi.raw)};
#endif
}

// Float → int32 by truncation for values known to be in range: one instruction, without the
// out-of-range fix-up Highway's ConvertTo adds.
HWY_INLINE VI truncToInt(VF v) {
#if HWY_TARGET <= HWY_AVX3
    return VI{_mm512_cvttps_epi32(v.raw)};
#elif HWY_TARGET == HWY_AVX2
    return VI{_mm256_cvttps_epi32(v.raw)};
#else
    return VI{_mm_cvttps_epi32(v.raw)};
#endif
}

// Per-lane 32-bit values → the pair layout: "lo" holds pixels 4k, 4k+1 of each block, "hi"
// pixels 4k+2, 4k+3, each value repeated for the pixel's four channel words.
struct Pair16 {
    V16 lo, hi;
};
HWY_INLINE Pair16 perChannelWords(VU dword_with_both_words) {
    const DU du;
    const D16 d16;
    return {hn::BitCast(d16, hn::InterleaveLower(du, dword_with_both_words, dword_with_both_words)),
            hn::BitCast(d16, hn::InterleaveUpper(du, dword_with_both_words, dword_with_both_words))};
}

// One layer's sampling constants, in the form the lanes use.
struct LayerC {
    const uint8_t* texels;
    int width, height;
    VF inv128, off128_x, max128_x, inv, off_y, max_y, max_y0, width_f;
    VI max_x0;
    bool pair_fetch;  // at least 2×2 texels: the two taps of a row are one 64-bit fetch
    bool row_loads;   // wide enough for the contiguous path
};

LayerC layerConstants(const KernelLayer& l) {
    const DF df;
    const DI di;
    LayerC c;
    c.texels = l.texels;
    c.width = l.width;
    c.height = l.height;
    c.inv128 = hn::Set(df, l.inv_scale * kSubTexel);
    c.off128_x = hn::Set(df, l.offset_x * kSubTexel);
    c.max128_x = hn::Set(df, static_cast<float>(l.width - 1) * kSubTexel);
    c.inv = hn::Set(df, l.inv_scale);
    c.off_y = hn::Set(df, l.offset_y);
    c.max_y = hn::Set(df, static_cast<float>(l.height - 1));
    c.max_y0 = hn::Set(df, l.height >= 2 ? static_cast<float>(l.height - 2) : 0.0f);
    c.width_f = hn::Set(df, static_cast<float>(l.width));
    c.max_x0 = hn::Set(di, l.width >= 2 ? l.width - 2 : 0);
    c.pair_fetch = l.width >= 2 && l.height >= 2;
    c.row_loads = c.pair_fetch && l.width >= 32;
    return c;
}

// Texel pairs of the pixels' two rows: bytes (left, right) of each channel side by side, in the
// pair layout (see perChannelWords).
struct Taps {
    V8 lo0, hi0, lo1, hi1;
};

// Left and right taps of rows 0 and 1 as whole texels, one per lane, interleaved into pairs.
HWY_INLINE Taps pairUp(VU left0, VU right0, VU left1, VU right1) {
    const D8 d8;
    return {hn::InterleaveLower(d8, hn::BitCast(d8, left0), hn::BitCast(d8, right0)),
            hn::InterleaveUpper(d8, hn::BitCast(d8, left0), hn::BitCast(d8, right0)),
            hn::InterleaveLower(d8, hn::BitCast(d8, left1), hn::BitCast(d8, right1)),
            hn::InterleaveUpper(d8, hn::BitCast(d8, left1), hn::BitCast(d8, right1))};
}

struct KernelConsts {
    VF iota;
    VI pair_order;  // lane permutation putting "lo" pixels first, "hi" pixels second
    V8 pair_bytes;  // within a 64-bit (left, right) texel pair: bytes to (left, right) per channel
};

KernelConsts kernelConsts() {
    const DF df;
    const DI di;
    const D8 d8;
    KernelConsts k;
    const VI lane = hn::Iota(di, 0);
    k.iota = hn::ConvertTo(df, lane);
    // j < N/2 → pixel 4·(j/2) + j%2; j ≥ N/2 → the same + 2.
    const int half = static_cast<int>(hn::Lanes(di)) / 2;
    const VI j = hn::Sub(lane, hn::IfThenElseZero(hn::Gt(lane, hn::Set(di, half - 1)),
                                                  hn::Set(di, half)));
    k.pair_order = hn::Or(hn::Or(hn::ShiftLeft<2>(hn::ShiftRight<1>(j)),
                                 hn::And(j, hn::Set(di, 1))),
                          hn::IfThenElseZero(hn::Gt(lane, hn::Set(di, half - 1)), hn::Set(di, 2)));
    const auto byte = hn::Iota(d8, 0);
    // Byte b of each 8-byte pair → source byte (b/2) + 4·(b%2) of the same pair.
    const auto within = hn::And(byte, hn::Set(d8, 7));
    k.pair_bytes = hn::Add(
        hn::Sub(byte, within),
        hn::Add(hn::ShiftRight<1>(within), hn::ShiftLeft<2>(hn::And(within, hn::Set(d8, 1)))));
    return k;
}

// Row 0's and row 1's taps by gathers. Pair fetch: the left tap stops one short of the right
// edge (the right tap then weighs 1), so the 64-bit fetch never passes the end of a row.
HWY_INLINE Taps gatherTaps(const LayerC& c, const KernelConsts& k, VI x0, VF fly) {
    const DI di;
    const DU du;
    const VI i00 = hn::Add(truncToInt(hn::Mul(fly, c.width_f)), x0);
    if (c.pair_fetch) {
        const hn::Half<DI> dh;
        const hn::Repartition<int64_t, DI> di64;
        const hn::Repartition<uint64_t, DI> du64;
        const D8 d8;
        const VI ordered = hn::TableLookupLanes(i00, hn::IndicesFromVec(di, k.pair_order));
        const auto lo = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::LowerHalf(dh, ordered)));
        const auto hi = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::UpperHalf(dh, ordered)));
        const auto* row0 = reinterpret_cast<const uint64_t*>(c.texels);
        const auto* row1 = reinterpret_cast<const uint64_t*>(c.texels + size_t{4} * c.width);
        auto split = [&](hn::Vec<decltype(du64)> pairs) {
            return hn::TableLookupBytes(hn::BitCast(d8, pairs), k.pair_bytes);
        };
        return {split(hn::GatherOffset(du64, row0, lo)), split(hn::GatherOffset(du64, row0, hi)),
                split(hn::GatherOffset(du64, row1, lo)), split(hn::GatherOffset(du64, row1, hi))};
    }
    // A layer one texel wide or high: the tap beyond it is the edge texel itself.
    const auto* base = reinterpret_cast<const uint32_t*>(c.texels);
    const VI dx = hn::Set(di, c.width >= 2 ? 1 : 0);
    const VI i01 = hn::Add(i00, hn::Set(di, c.height >= 2 ? c.width : 0));
    return pairUp(hn::GatherIndex(du, base, i00), hn::GatherIndex(du, base, hn::Add(i00, dx)),
                  hn::GatherIndex(du, base, i01), hn::GatherIndex(du, base, hn::Add(i01, dx)));
}

#if QVR_UCA_ROW_LOADS
// The contiguous path: when the vector's left taps lie within 31 texels of one another and
// within two neighbouring rows, load 32 texels of each row involved and pick every tap with a
// two-table lane permute. Bit-identical to the gathers; false when the taps are too scattered.
HWY_INLINE bool rowLoadTaps(const LayerC& c, VI x0, VI y0, Taps& taps) {
    const DI di;
    const DU du;
    const __m512i x0r = x0.raw, y0r = y0.raw;
    const __m512i last = _mm512_set1_epi32(15);
    // Rows of the map are nearly monotonic, so the smaller end lane is (nearly) the minimum;
    // the range check below catches any lane that is not.
    const __m512i x_min = _mm512_min_epi32(_mm512_broadcastd_epi32(_mm512_castsi512_si128(x0r)),
                                           _mm512_permutexvar_epi32(last, x0r));
    const __m512i start = _mm512_min_epi32(x_min, _mm512_set1_epi32(c.width - 32));
    const __m512i dx = _mm512_sub_epi32(x0r, start);
    const __m512i y_min = _mm512_min_epi32(_mm512_broadcastd_epi32(_mm512_castsi512_si128(y0r)),
                                           _mm512_permutexvar_epi32(last, y0r));
    const __m512i dy = _mm512_sub_epi32(y0r, y_min);
    if (_mm512_cmpgt_epu32_mask(dx, _mm512_set1_epi32(30)) != 0 ||
        _mm512_cmpgt_epu32_mask(dy, _mm512_set1_epi32(1)) != 0) {
        return false;
    }
    const int first_x = _mm_cvtsi128_si32(_mm512_castsi512_si128(start));
    const int first_y = _mm_cvtsi128_si32(_mm512_castsi512_si128(y_min));
    const uint32_t* row = reinterpret_cast<const uint32_t*>(c.texels) +
                          static_cast<size_t>(first_y) * static_cast<size_t>(c.width) +
                          static_cast<size_t>(first_x);
    const __m512i dx1 = _mm512_add_epi32(dx, _mm512_set1_epi32(1));
    auto pick = [&](const uint32_t* r, __m512i& left, __m512i& right) {
        const __m512i a = _mm512_loadu_si512(r);
        const __m512i b = _mm512_loadu_si512(r + 16);
        left = _mm512_permutex2var_epi32(a, dx, b);
        right = _mm512_permutex2var_epi32(a, dx1, b);
    };
    __m512i l0, r0, l1, r1;
    pick(row, l0, r0);
    pick(row + c.width, l1, r1);
    const __mmask16 lower = _mm512_cmpeq_epi32_mask(dy, _mm512_set1_epi32(1));
    if (lower != 0) {
        // Lanes one row down take rows 1 and 2.
        __m512i l2, r2;
        pick(row + 2 * static_cast<size_t>(c.width), l2, r2);
        l0 = _mm512_mask_mov_epi32(l0, lower, l1);
        r0 = _mm512_mask_mov_epi32(r0, lower, r1);
        l1 = _mm512_mask_mov_epi32(l1, lower, l2);
        r1 = _mm512_mask_mov_epi32(r1, lower, r2);
    }
    (void)di;
    taps = pairUp(VU{l0}, VU{r0}, VU{l1}, VU{r1});
    (void)du;
    return true;
}
#endif

// q = −128·(bilinear value) per channel of one layer at the lanes' points (docs/UCA.md,
// "Fixed-point filter"), in the pair layout.
HWY_INLINE Pair16 sampleLayer(const LayerC& c, const KernelConsts& k, VF px, VF py,
                              bool force_gather) {
    const DF df;
    const DI di;
    const DU du;
    const DU16 du16;
    const D16 d16;
    const D8 d8;
    const VF zero = hn::Zero(df);
    // Clamping the texel coordinate to [0, size − 1] is clamp-to-edge.
    const VF xq = hn::Min(hn::Max(hn::MulAdd(px, c.inv128, c.off128_x), zero), c.max128_x);
    const VI xi = truncToInt(hn::Add(xq, hn::Set(df, 0.5f)));
    const VI x0 = hn::Min(hn::ShiftRight<7>(xi), c.max_x0);
    const VI wx = hn::Sub(xi, hn::ShiftLeft<7>(x0));
    const VF ly = hn::Min(hn::Max(hn::MulAdd(py, c.inv, c.off_y), zero), c.max_y);
    const VF fly = hn::Min(hn::Floor(ly), c.max_y0);
    const VF wy = hn::Sub(ly, fly);
    const VI wy15 = truncToInt(hn::Min(hn::Add(hn::Mul(wy, hn::Set(df, static_cast<float>(kWeightOne))),
                            hn::Set(df, 0.5f)),
                    hn::Set(df, static_cast<float>(kWeightOne - 1))));
    Taps taps;
#if QVR_UCA_ROW_LOADS
    if (force_gather || !c.row_loads || !rowLoadTaps(c, x0, truncToInt(fly), taps))
        taps = gatherTaps(c, k, x0, fly);
#else
    (void)force_gather;
    taps = gatherTaps(c, k, x0, fly);
#endif
    // Horizontal weights as signed bytes (w − 128, −w): pmaddubsw then gives
    // −(left·(128 − w) + right·w), at most 255·128 in magnitude, never saturating.
    const auto w = hn::BitCast(du16, hn::Or(wx, hn::ShiftLeft<16>(wx)));
    const auto wb = hn::Or(hn::ShiftLeft<8>(hn::Sub(hn::Zero(du16), w)),
                           hn::Xor(w, hn::Set(du16, 0x80)));
    const Pair16 wxp = perChannelWords(hn::BitCast(du, wb));
    const V16 top_lo = mulPairs(taps.lo0, hn::BitCast(d8, wxp.lo));
    const V16 top_hi = mulPairs(taps.hi0, hn::BitCast(d8, wxp.hi));
    const V16 bot_lo = mulPairs(taps.lo1, hn::BitCast(d8, wxp.lo));
    const V16 bot_hi = mulPairs(taps.hi1, hn::BitCast(d8, wxp.hi));
    const Pair16 wyp = perChannelWords(hn::BitCast(du, hn::Or(wy15, hn::ShiftLeft<16>(wy15))));
    (void)d16;
    return {hn::Add(top_lo, hn::MulFixedPoint15(hn::Sub(bot_lo, top_lo), wyp.lo)),
            hn::Add(top_hi, hn::MulFixedPoint15(hn::Sub(bot_hi, top_hi), wyp.hi))};
}

// a + (b − a)·t in fixed point, exactly b where t = 1 (32768, which reads as −32768 in i16).
HWY_INLINE V16 lerpQ(V16 t, V16 a, V16 b) {
    const D16 d16;
    const V16 mixed = hn::Add(a, hn::MulFixedPoint15(hn::Sub(b, a), t));
    return hn::IfThenElse(hn::Eq(t, hn::Set(d16, static_cast<int16_t>(-32768))), b, mixed);
}

HWY_INLINE VI rampWeight(float c_hi, float inv, VF cos_e) {
    const DF df;
    const DI di;
    const VF t = hn::Min(
        hn::Max(hn::Mul(hn::Sub(hn::Set(df, c_hi), cos_e), hn::Set(df, inv)), hn::Zero(df)),
        hn::Set(df, 1.0f));
    return truncToInt(
        hn::Add(hn::Mul(t, hn::Set(df, static_cast<float>(kWeightOne))), hn::Set(df, 0.5f)));
}

// Bytes of q: (64 − q) >> 7, packed back into pixel order.
HWY_INLINE VU toBytes(const Pair16& q) {
    const D16 d16;
    const DU16 du16;
    const DU du;
    const V16 k64 = hn::Set(d16, 64);
    const V16 lo = hn::BitCast(d16, hn::ShiftRight<7>(hn::BitCast(du16, hn::Sub(k64, q.lo))));
    const V16 hi = hn::BitCast(d16, hn::ShiftRight<7>(hn::BitCast(du16, hn::Sub(k64, q.hi))));
    return hn::BitCast(du, packBlocks(lo, hi));
}

struct MapV {
    VF px, py, cos_e;
    MF valid;
};

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
        m.valid = hn::FirstN(df, hn::Lanes(df));
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
        const VF depth = hn::NegMulAdd(
            f, hn::MulAdd(xt, hn::Set(df, r.mz), hn::Set(df, r.cz_row)), hn::Set(df, r.dz));
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

struct TileSlots {
    LayerC layer[3];
    int count;
    uint8_t mask;
    bool single;
    int single_slot;
};

// Eq. 4 for a vector of pixels under one chroma scale's map, as bytes (alpha not set); lanes
// off the rendered image come back in `valid`.
HWY_INLINE VU shadeVector(const KernelParams& p, const RowMap& r, const TileSlots& s,
                          const KernelConsts& k, VF u, VF v, float chroma, MF& valid) {
    const DI di;
    const DU du;
    const MapV m = mapPixels(p, r, u, v, chroma, !s.single);
    valid = m.valid;
    const VF px = m.px, py = m.py, cos_e = m.cos_e;
    if (s.single)
        return toBytes(sampleLayer(s.layer[s.single_slot], k, px, py, p.force_gather));
    const VI t0 = rampWeight(p.border_c_hi[0], p.border_inv[0], cos_e);
    const VI t1 = rampWeight(p.border_c_hi[1], p.border_inv[1], cos_e);
    const VI zero_i = hn::Zero(di);
    const VI one = hn::Set(di, kWeightOne);
    // A layer whose weight is 0 in every lane is not sampled: the nested lerps ignore it.
    const bool need[3] = {
        !hn::AllFalse(di, hn::Lt(t0, one)),
        !hn::AllFalse(di, hn::And(hn::Gt(t0, zero_i), hn::Lt(t1, one))),
        !hn::AllFalse(di, hn::And(hn::Gt(t0, zero_i), hn::Gt(t1, zero_i)))};
    const D16 d16;
    Pair16 q[3] = {{hn::Zero(d16), hn::Zero(d16)},
                   {hn::Zero(d16), hn::Zero(d16)},
                   {hn::Zero(d16), hn::Zero(d16)}};
    for (int slot = 0; slot < s.count; ++slot) {
        if ((s.mask & (1u << slot)) != 0 && need[slot])
            q[slot] = sampleLayer(s.layer[slot], k, px, py, p.force_gather);
    }
    const Pair16 w0 = perChannelWords(hn::BitCast(du, hn::Or(t0, hn::ShiftLeft<16>(t0))));
    const Pair16 w1 = perChannelWords(hn::BitCast(du, hn::Or(t1, hn::ShiftLeft<16>(t1))));
    const Pair16 blended = {lerpQ(w0.lo, q[0].lo, lerpQ(w1.lo, q[1].lo, q[2].lo)),
                            lerpQ(w0.hi, q[0].hi, lerpQ(w1.hi, q[1].hi, q[2].hi))};
    return toBytes(blended);
}

}  // namespace
#endif  // QVR_UCA_VECTOR

void UcaTile(const KernelParams& p, const TileJob& job) {
#if !QVR_UCA_VECTOR
    // No byte shuffles on this target: the twin is the same arithmetic.
    ucaTileScalar(p, job);
#else
    const DF df;
    const DI di;
    const DU du;
    const int lanes = static_cast<int>(hn::Lanes(df));
    HWY_ALIGN uint32_t tail[HWY_MAX_BYTES / sizeof(uint32_t)];
    const uintptr_t vector_bytes = static_cast<uintptr_t>(lanes) * sizeof(uint32_t);
    auto store = [&](VU packed, uint32_t* row, int x) {
        if (x + lanes <= job.x1) {
            if (job.stream && (reinterpret_cast<uintptr_t>(row + x) & (vector_bytes - 1)) == 0) {
                hn::Stream(packed, du, row + x);
            } else {
                hn::StoreU(packed, du, row + x);
            }
        } else {
            hn::Store(packed, du, tail);
            std::memcpy(row + x, tail, static_cast<size_t>(job.x1 - x) * sizeof(uint32_t));
        }
    };
    const VU black = hn::Set(du, kOpaqueBlack);
    if (job.slot_mask == 0) {
        for (int y = job.y0; y < job.y1; ++y) {
            auto* row =
                reinterpret_cast<uint32_t*>(job.out) + static_cast<size_t>(y) * job.out_stride_px;
            for (int x = job.x0; x < job.x1; x += lanes)
                store(black, row, x);
        }
        if (job.stream)
            hwy::FlushStream();
        return;
    }
    const KernelConsts k = kernelConsts();
    TileSlots s;
    s.count = p.slot_count;
    s.mask = job.slot_mask;
    s.single = (job.slot_mask & (job.slot_mask - 1)) == 0;
    s.single_slot = job.slot_mask == 1 ? 0 : (job.slot_mask == 2 ? 1 : 2);
    for (int slot = 0; slot < p.slot_count; ++slot) {
        if ((job.slot_mask & (1u << slot)) != 0)
            s.layer[slot] = layerConstants(p.slots[slot]);
    }
    const float scales[3] = {1.0f, p.chroma_red, p.chroma_blue};
    for (int y = job.y0; y < job.y1; ++y) {
        auto* row =
            reinterpret_cast<uint32_t*>(job.out) + static_cast<size_t>(y) * job.out_stride_px;
        const VF v = hn::Set(df, static_cast<float>(y));
        const RowMap r = rowMap(p, static_cast<float>(y));
        for (int x = job.x0; x < job.x1; x += lanes) {
            const VF u = hn::Add(k.iota, hn::Set(df, static_cast<float>(x)));
            VU packed;
            MF valid;
            if (!p.chroma) {
                const VU bytes = shadeVector(p, r, s, k, u, v, 1.0f, valid);
                packed = hn::IfThenElse(hn::RebindMask(du, valid), hn::Or(bytes, black), black);
            } else {
                // Lateral chromatic aberration: each channel has its own map and validity.
                const uint32_t channel_mask[3] = {0x0000FF00u, 0x000000FFu, 0x00FF0000u};
                packed = black;
                for (int c = 0; c < 3; ++c) {
                    const VU bytes = shadeVector(p, r, s, k, u, v, scales[c], valid);
                    packed = hn::Or(packed,
                                    hn::IfThenElseZero(hn::RebindMask(du, valid),
                                                       hn::And(bytes, hn::Set(du, channel_mask[c]))));
                }
            }
            store(packed, row, x);
        }
    }
    // Streaming stores are weakly ordered: make them visible before the tile counts as done.
    if (job.stream)
        hwy::FlushStream();
#endif
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

void ucaTileSimd(const KernelParams& p, const TileJob& job) {
    HWY_DYNAMIC_DISPATCH(UcaTile)(p, job);
}
}  // namespace qvr::detail
#endif
