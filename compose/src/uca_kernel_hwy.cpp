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

// Byte c of every RGBA8 texel as a float: one byte shuffle (zeroing the other three bytes of
// each lane) instead of a shift and a mask.
template <int kChannel>
HWY_INLINE VF channel(VU texel) {
    const DF df;
    const DI di;
    const DU du;
#if HWY_TARGET == HWY_SCALAR
    // One lane cannot be viewed as bytes; shift and mask instead.
    return hn::ConvertTo(
        df, hn::BitCast(di, hn::And(hn::ShiftRight<8 * kChannel>(texel), hn::Set(du, 0xFFu))));
#else
    const hn::Repartition<uint8_t, DU> d8;
    // Shuffle indices are byte positions within each 16-byte block: lane j of a block holds its
    // texel in bytes 4j…4j+3.
    const VU lane_in_block = hn::And(hn::Iota(du, 0u), hn::Set(du, 3u));
    const VU index = hn::Add(hn::ShiftLeft<2>(lane_in_block),
                             hn::Set(du, 0x80808000u | static_cast<uint32_t>(kChannel)));
    const auto pick = hn::BitCast(d8, index);
    const auto bytes = hn::TableLookupBytesOr0(hn::BitCast(d8, texel), pick);
    return hn::ConvertTo(df, hn::BitCast(di, bytes));
#endif
}

HWY_INLINE VF lerp(VF w, VF a, VF b) {
    return hn::MulAdd(w, hn::Sub(b, a), a);
}

HWY_INLINE Rgb sampleLayer(const KernelLayer& l, VF px, VF py) {
    const DF df;
    const DI di;
    const DU du;
    // Clamping the texel coordinate to [0, size − 1] is clamp-to-edge: at the edge the weight
    // of the tap beyond it is 0, and that tap is redirected onto the edge texel.
    const VF max_x = hn::Set(df, static_cast<float>(l.width - 1));
    const VF max_y = hn::Set(df, static_cast<float>(l.height - 1));
    const VF zero = hn::Zero(df);
    const VF lx = hn::Min(
        hn::Max(hn::MulAdd(px, hn::Set(df, l.inv_scale), hn::Set(df, l.offset_x)), zero), max_x);
    const VF ly = hn::Min(
        hn::Max(hn::MulAdd(py, hn::Set(df, l.inv_scale), hn::Set(df, l.offset_y)), zero), max_y);
    const auto* base = reinterpret_cast<const uint32_t*>(l.texels);
    VU t00, t10, t01, t11;
    VF flx, fly;
#if HWY_TARGET != HWY_SCALAR
    if (l.width >= 2 && l.height >= 2) {
        // The two taps of a row are neighbours in memory: fetch them as one 64-bit element, half
        // the gathered elements. The left tap stops one short of the edge, where the weight of
        // the right tap becomes exactly 1, so no fetch passes the end of a row.
        flx = hn::Min(hn::Floor(lx), hn::Sub(max_x, hn::Set(df, 1.0f)));
        fly = hn::Min(hn::Floor(ly), hn::Sub(max_y, hn::Set(df, 1.0f)));
        // Texel index in float is exact: layers hold fewer than 2^24 texels (validateFrame).
        const VI i00 = truncToInt(hn::MulAdd(fly, hn::Set(df, static_cast<float>(l.width)), flx));
        const hn::Half<DI> dh;
        const hn::Repartition<uint64_t, DU> d64;
        const hn::RebindToSigned<decltype(d64)> di64;
        const auto* base64 = reinterpret_cast<const uint64_t*>(l.texels);
        const auto lo = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::LowerHalf(dh, i00)));
        const auto hi = hn::ShiftLeft<2>(hn::PromoteTo(di64, hn::UpperHalf(dh, i00)));
        const auto row_bytes = hn::Set(di64, int64_t{4} * l.width);
        const VU r0_lo = hn::BitCast(du, hn::GatherOffset(d64, base64, lo));
        const VU r0_hi = hn::BitCast(du, hn::GatherOffset(d64, base64, hi));
        const VU r1_lo = hn::BitCast(du, hn::GatherOffset(d64, base64, hn::Add(lo, row_bytes)));
        const VU r1_hi = hn::BitCast(du, hn::GatherOffset(d64, base64, hn::Add(hi, row_bytes)));
        t00 = hn::ConcatEven(du, r0_hi, r0_lo);
        t10 = hn::ConcatOdd(du, r0_hi, r0_lo);
        t01 = hn::ConcatEven(du, r1_hi, r1_lo);
        t11 = hn::ConcatOdd(du, r1_hi, r1_lo);
    } else
#endif
    {
        flx = hn::Floor(lx);
        fly = hn::Floor(ly);
        const VI i00 =
            hn::ConvertTo(di, hn::MulAdd(fly, hn::Set(df, static_cast<float>(l.width)), flx));
        const VI step_x =
            hn::IfThenElseZero(hn::RebindMask(di, hn::Lt(flx, max_x)), hn::Set(di, 1));
        const VI step_y =
            hn::IfThenElseZero(hn::RebindMask(di, hn::Lt(fly, max_y)), hn::Set(di, l.width));
        const VI i01 = hn::Add(i00, step_y);
        t00 = hn::GatherIndex(du, base, i00);
        t10 = hn::GatherIndex(du, base, hn::Add(i00, step_x));
        t01 = hn::GatherIndex(du, base, i01);
        t11 = hn::GatherIndex(du, base, hn::Add(i01, step_x));
    }
    const VF wx = hn::Sub(lx, flx);
    const VF wy = hn::Sub(ly, fly);
    Rgb out;
    out.r = lerp(wy, lerp(wx, channel<0>(t00), channel<0>(t10)),
                 lerp(wx, channel<0>(t01), channel<0>(t11)));
    out.g = lerp(wy, lerp(wx, channel<1>(t00), channel<1>(t10)),
                 lerp(wx, channel<1>(t01), channel<1>(t11)));
    out.b = lerp(wy, lerp(wx, channel<2>(t00), channel<2>(t10)),
                 lerp(wx, channel<2>(t01), channel<2>(t11)));
    return out;
}

// Eq. 4 for a vector of pixels; lanes off the rendered image come back in `valid`.
HWY_INLINE Rgb shade(const KernelParams& p, const RowMap& r, VF u, VF v, float chroma,
                     uint8_t slot_mask, MF& valid) {
    const DF df;
    const bool single = (slot_mask & (slot_mask - 1)) == 0;
    const MapV m = mapPixels(p, r, u, v, chroma, !single);
    Rgb rgb;
    if (single) {
        const int k = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        rgb = sampleLayer(p.slots[k], m.px, m.py);
    } else {
        const VF zero = hn::Zero(df);
        const VF one = hn::Set(df, 1.0f);
        const VF t1 = hn::Min(hn::Max(hn::Mul(hn::Sub(hn::Set(df, p.border_c_hi[0]), m.cos_e),
                                              hn::Set(df, p.border_inv[0])),
                                      zero),
                              one);
        const VF t2 = hn::Min(hn::Max(hn::Mul(hn::Sub(hn::Set(df, p.border_c_hi[1]), m.cos_e),
                                              hn::Set(df, p.border_inv[1])),
                                      zero),
                              one);
        const VF t12 = hn::Mul(t1, t2);
        const VF w[3] = {hn::Sub(one, t1), hn::Sub(t1, t12), t12};
        rgb = {zero, zero, zero};
        for (int k = 0; k < p.slot_count; ++k) {
            if ((slot_mask & (1u << k)) == 0)
                continue;
            // Lanes outside this layer's ramp have weight 0; skip the gathers when all do.
            if (hn::AllFalse(df, hn::Gt(w[k], zero)))
                continue;
            const Rgb s = sampleLayer(p.slots[k], m.px, m.py);
            rgb.r = hn::MulAdd(w[k], s.r, rgb.r);
            rgb.g = hn::MulAdd(w[k], s.g, rgb.g);
            rgb.b = hn::MulAdd(w[k], s.b, rgb.b);
        }
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

HWY_INLINE VU shadePacked(const KernelParams& p, const RowMap& r, VF u, VF v, uint8_t slot_mask) {
    const DU du;
    MF valid;
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

}  // namespace

void UcaTile(const KernelParams& p, const TileJob& job) {
    const DF df;
    const DU du;
    const int lanes = static_cast<int>(hn::Lanes(df));
    const VF iota = hn::Iota(df, 0.0f);
    HWY_ALIGN uint32_t tail[HWY_MAX_BYTES / sizeof(uint32_t)];
    const uintptr_t vector_bytes = static_cast<uintptr_t>(lanes) * sizeof(uint32_t);
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
            if (x + lanes <= job.x1) {
                if (job.stream &&
                    (reinterpret_cast<uintptr_t>(row + x) & (vector_bytes - 1)) == 0) {
                    hn::Stream(packed, du, row + x);
                } else {
                    hn::StoreU(packed, du, row + x);
                }
            } else {
                hn::Store(packed, du, tail);
                std::memcpy(row + x, tail, static_cast<size_t>(job.x1 - x) * sizeof(uint32_t));
            }
        }
    }
    // Streaming stores are weakly ordered: make them visible before the tile counts as done.
    if (job.stream)
        hwy::FlushStream();
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
