// The vectorised bilinear span (bilinear_span.h) with Highway: a vector of taps along a span at a
// time, each tap's four texels fetched with gathers and filtered in 32-bit integer lanes by the
// scalar twin's arithmetic (bilinear_span.cpp), so both write the same bytes. A span whose ends
// leave the 32-bit range (a ray grazing the eye's plane) takes the scalar twin.
#include <algorithm>
#include <cstring>
#include <iterator>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "bilinear_span_hwy.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "qvr/compose/bilinear_span.h"
#include "qvr/core/check.h"

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // see uca_kernel_hwy.cpp
#endif

HWY_BEFORE_NAMESPACE();
namespace qvr::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using DI = hn::ScalableTag<int32_t>;
using DU = hn::RebindToUnsigned<DI>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;

// Channel C of packed RGBA8 taps, filtered: the scalar twin's two lerps and rounding.
template <int C>
HWY_INLINE VU filterChannel(VU t00, VU t10, VU t01, VU t11, VU fx, VU ifx, VU fy, VU ify) {
    const DU du;
    const VU mask = hn::Set(du, 255u);
    const VU top = hn::Add(hn::Mul(hn::And(hn::ShiftRight<8 * C>(t00), mask), ifx),
                           hn::Mul(hn::And(hn::ShiftRight<8 * C>(t10), mask), fx));
    const VU bottom = hn::Add(hn::Mul(hn::And(hn::ShiftRight<8 * C>(t01), mask), ifx),
                              hn::Mul(hn::And(hn::ShiftRight<8 * C>(t11), mask), fx));
    const VU v = hn::Add(hn::Add(hn::Mul(top, ify), hn::Mul(bottom, fy)), hn::Set(du, 32768u));
    return hn::ShiftLeft<8 * C>(hn::ShiftRight<16>(v));
}

// One axis of a vector of taps: the clamped coordinate's texel, its neighbour and the weights.
struct Axis {
    VI t0, t1;
    VU f, inv_f;
};

HWY_INLINE Axis axisOf(VI coord, int32_t max_fixed, int32_t last) {
    const DI di;
    const DU du;
    const VI c = hn::Min(hn::Max(coord, hn::Zero(di)), hn::Set(di, max_fixed));
    Axis a;
    a.t0 = hn::ShiftRight<16>(c);
    a.t1 = hn::Min(hn::Add(a.t0, hn::Set(di, 1)), hn::Set(di, last));
    a.f = hn::And(hn::BitCast(du, hn::ShiftRight<8>(c)), hn::Set(du, 255u));
    a.inv_f = hn::Sub(hn::Set(du, 256u), a.f);
    return a;
}

// A span whose every tap's coordinates fit in int32 (checked by the caller).
void spanVector(const ImageRgba8& src, const FixedSpan& s, uint8_t* dst) {
    const DI di;
    const DU du;
    const int lanes = static_cast<int>(hn::Lanes(di));
    const int w = src.width(), h = src.height();
    const auto* base = reinterpret_cast<const uint32_t*>(src.data());
    const int32_t max_x = (w - 1) << 16, max_y = (h - 1) << 16;
    const VI step_x = hn::Mul(hn::Iota(di, 0), hn::Set(di, static_cast<int32_t>(s.sx)));
    const VI step_y = hn::Mul(hn::Iota(di, 0), hn::Set(di, static_cast<int32_t>(s.sy)));
    const VI width = hn::Set(di, w);
    const VU opaque = hn::Set(du, 0xFF000000u);
    for (int k = 0; k < s.n; k += lanes) {
        const Axis ax = axisOf(hn::Add(hn::Set(di, static_cast<int32_t>(s.x + k * s.sx)), step_x),
                               max_x, w - 1);
        const Axis ay = axisOf(hn::Add(hn::Set(di, static_cast<int32_t>(s.y + k * s.sy)), step_y),
                               max_y, h - 1);
        const VI row0 = hn::Mul(ay.t0, width), row1 = hn::Mul(ay.t1, width);
        const VU t00 = hn::GatherIndex(du, base, hn::Add(row0, ax.t0));
        const VU t10 = hn::GatherIndex(du, base, hn::Add(row0, ax.t1));
        const VU t01 = hn::GatherIndex(du, base, hn::Add(row1, ax.t0));
        const VU t11 = hn::GatherIndex(du, base, hn::Add(row1, ax.t1));
        VU out =
            hn::Or(opaque, filterChannel<0>(t00, t10, t01, t11, ax.f, ax.inv_f, ay.f, ay.inv_f));
        out = hn::Or(out, filterChannel<1>(t00, t10, t01, t11, ax.f, ax.inv_f, ay.f, ay.inv_f));
        out = hn::Or(out, filterChannel<2>(t00, t10, t01, t11, ax.f, ax.inv_f, ay.f, ay.inv_f));
        uint8_t* at = dst + static_cast<size_t>(k) * 4;
        if (k + lanes <= s.n) {
            hn::StoreU(out, du, reinterpret_cast<uint32_t*>(at));
        } else {
            HWY_ALIGN uint32_t tail[hn::MaxLanes(du)];
            hn::Store(out, du, tail);
            std::memcpy(at, tail, static_cast<size_t>(s.n - k) * 4);
        }
    }
}

// Whether every lane spanVector computes, those past the span's end in its last vector too,
// holds its coordinates in int32 (then no lane's arithmetic overflows, on any target).
bool fitsInt32(const FixedSpan& s) {
    constexpr int64_t kLimit = int64_t(1) << 30;
    const int64_t lanes = static_cast<int64_t>(hn::Lanes(DI()));
    const int64_t last = std::max<int64_t>(1, (s.n + lanes - 1) / lanes) * lanes - 1;
    if (s.sx < -kLimit || s.sx > kLimit || s.sy < -kLimit || s.sy > kLimit)
        return false;
    const int64_t ends[4] = {s.x, s.y, s.x + last * s.sx, s.y + last * s.sy};
    return std::all_of(std::begin(ends), std::end(ends),
                       [](int64_t v) { return v >= -kLimit && v <= kLimit; });
}

}  // namespace

void BilinearSpans(const ImageRgba8& src, const FixedSpan* spans, size_t count, uint8_t* dst) {
    for (size_t i = 0; i < count; ++i) {
        if (fitsInt32(spans[i]))
            spanVector(src, spans[i], dst);
        else
            bilinearSpansScalar(src, spans + i, 1, dst);
        dst += static_cast<size_t>(std::max(spans[i].n, 0)) * 4;
    }
}

const char* SpanTargetName() {
    return hwy::TargetName(HWY_TARGET);
}

}  // namespace HWY_NAMESPACE
}  // namespace qvr::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace qvr {
namespace detail {
HWY_EXPORT(BilinearSpans);
HWY_EXPORT(SpanTargetName);
}  // namespace detail

void bilinearSpans(const ImageRgba8& src, const FixedSpan* spans, size_t count, uint8_t* dst) {
    QVR_CHECK(!src.empty());
    HWY_DYNAMIC_DISPATCH(detail::BilinearSpans)(src, spans, count, dst);
}

const char* bilinearSpanTarget() {
    return HWY_DYNAMIC_DISPATCH(detail::SpanTargetName)();
}
}  // namespace qvr
#endif
