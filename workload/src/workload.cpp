// Per-frame workload helpers: ring sums, bits-per-pixel interpolation, periphery bytes of a
// plan, and the invariants every trace satisfies.
#include "qvr/workload/workload.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace qvr {

double sumWithinDeg(const std::vector<double>& per_ring, double ring_deg, double e_deg) {
    if (!(e_deg > 0.0) || per_ring.empty())  // also NaN
        return 0.0;
    const double rings = e_deg / ring_deg;
    if (rings >= static_cast<double>(per_ring.size()))
        return sumTotal(per_ring);
    const size_t whole = static_cast<size_t>(std::floor(rings));
    double sum = 0.0;
    const size_t n = std::min(whole, per_ring.size());
    for (size_t k = 0; k < n; ++k)
        sum += per_ring[k];
    if (whole < per_ring.size())
        sum += per_ring[whole] * (rings - static_cast<double>(whole));
    return sum;
}

double sumTotal(const std::vector<double>& per_ring) {
    double sum = 0.0;
    for (double v : per_ring)
        sum += v;
    return sum;
}

uint32_t frameContentKey(const Pose& head) {
    const double values[] = {head.position_m.x * 1e4,  head.position_m.y * 1e4,
                             head.position_m.z * 1e4,  head.orientation.w * 1e5,
                             head.orientation.x * 1e5, head.orientation.y * 1e5,
                             head.orientation.z * 1e5};
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the rounded values
    for (double v : values) {
        const int64_t q = std::isfinite(v) ? std::llround(v) : 0;
        for (int b = 0; b < 8; ++b) {
            h ^= static_cast<uint64_t>(q >> (8 * b)) & 0xffu;
            h *= 1099511628211ull;
        }
    }
    const auto key = static_cast<uint32_t>(h ^ (h >> 32));
    return key == 0 ? 1u : key;
}

double bitsPerPixelAt(const WorkloadHeader& header, const WorkloadFrame& frame, double scale) {
    const auto& s = header.scales;
    const auto& b = frame.bits_per_pixel;
    QVR_CHECK(!s.empty() && s.size() == b.size());
    if (scale <= s.front())
        return b.front();
    if (scale >= s.back())
        return b.back();
    const size_t hi = static_cast<size_t>(std::upper_bound(s.begin(), s.end(), scale) - s.begin());
    const size_t lo = hi - 1;
    // Coding cost per pixel follows a power law in scale closely, so interpolate in log-log.
    const double t = std::log(scale / s[lo]) / std::log(s[hi] / s[lo]);
    if (b[lo] <= 0.0 || b[hi] <= 0.0)
        return b[lo] + t * (b[hi] - b[lo]);
    return std::exp(std::log(b[lo]) + t * (std::log(b[hi]) - std::log(b[lo])));
}

PeripheryBytes peripheryBytes(const WorkloadHeader& header, const WorkloadFrame& frame,
                              const LayerPlan& plan) {
    PeripheryBytes bytes;
    // Pixel counts in a plan are per eye; both eyes are sent.
    if (plan.middle_pixels > 0)
        bytes.middle = 2.0 * static_cast<double>(plan.middle_pixels) *
                       bitsPerPixelAt(header, frame, plan.s1) / 8.0;
    if (plan.outer_pixels > 0)
        bytes.outer = 2.0 * static_cast<double>(plan.outer_pixels) *
                      bitsPerPixelAt(header, frame, plan.s2) / 8.0;
    return bytes;
}

namespace {
bool finiteNonNegative(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x) && x >= 0.0; });
}
}  // namespace

Status validateHeader(const WorkloadHeader& h) {
    if (!(h.ring_deg > 0.0 && h.ring_deg <= 10.0))
        return makeError(fmt::format("ring_deg {} is outside (0, 10]", h.ring_deg));
    if (h.rings < 1 || h.rings > kMaxRings)
        return makeError(fmt::format("rings {} is outside [1, {}]", h.rings, kMaxRings));
    if (h.ring_deg * h.rings < 45.0 || h.ring_deg * h.rings > 180.0)
        return makeError(fmt::format("rings cover {}°; they must reach between 45° and 180°",
                                     h.ring_deg * h.rings));
    if (h.scales.empty() || h.scales.size() > static_cast<size_t>(kMaxScales))
        return makeError(fmt::format("scales must hold 1 to {} values", kMaxScales));
    for (size_t i = 0; i < h.scales.size(); ++i) {
        if (!std::isfinite(h.scales[i]) || h.scales[i] < 1.0 || h.scales[i] > 1024.0)
            return makeError(fmt::format("scale {} is outside [1, 1024]", h.scales[i]));
        if (i > 0 && h.scales[i] <= h.scales[i - 1])
            return makeError("scales must be strictly increasing");
    }
    return Status::success();
}

Status validateFrame(const WorkloadHeader& h, const WorkloadFrame& f, double previous_time_ms) {
    if (f.triangles_per_ring.size() != static_cast<size_t>(h.rings))
        return makeError(
            fmt::format("{} triangle rings, header says {}", f.triangles_per_ring.size(), h.rings));
    if (f.pixels_per_ring.size() != static_cast<size_t>(h.rings))
        return makeError(
            fmt::format("{} pixel rings, header says {}", f.pixels_per_ring.size(), h.rings));
    if (f.bits_per_pixel.size() != h.scales.size())
        return makeError(fmt::format("{} bits-per-pixel values, header has {} scales",
                                     f.bits_per_pixel.size(), h.scales.size()));
    if (!finiteNonNegative(f.triangles_per_ring))
        return makeError("'tri' values must be finite and non-negative");
    if (!finiteNonNegative(f.pixels_per_ring))
        return makeError("'pix' values must be finite and non-negative");
    if (!finiteNonNegative(f.bits_per_pixel))
        return makeError("'bpp' values must be finite and non-negative");
    if (!f.bits_per_pixel_lossless.empty() && f.bits_per_pixel_lossless.size() != h.scales.size())
        return makeError(fmt::format("{} lossless bits-per-pixel values, header has {} scales",
                                     f.bits_per_pixel_lossless.size(), h.scales.size()));
    if (!finiteNonNegative(f.bits_per_pixel_lossless))
        return makeError("'bpp_lossless' values must be finite and non-negative");
    if (!std::isfinite(f.time_ms) || f.time_ms < previous_time_ms)
        return makeError("'t_ms' (time_ms) must be finite and non-decreasing");
    if (!std::isfinite(f.gaze.x_deg) || !std::isfinite(f.gaze.y_deg) ||
        std::fabs(f.gaze.x_deg) > 80.0 || std::fabs(f.gaze.y_deg) > 80.0)
        return makeError("gaze must be finite and within ±80°");
    const StaticSplit& s = f.static_split;
    if (!finiteNonNegative({s.fg_triangles, s.bg_bytes, s.depth_bytes}) ||
        !(s.fg_screen_fraction >= 0.0 && s.fg_screen_fraction <= 1.0))
        return makeError("static split values must be finite, non-negative, fraction in [0, 1]");
    return Status::success();
}

Expected<CodecModel> parseCodecModel(const std::string& name) {
    if (name == "stream")
        return CodecModel::kStream;
    if (name == "lossless")
        return CodecModel::kLossless;
    return makeError(
        fmt::format("codec model '{}': expected lossless (the paper's, §2.3) or stream", name));
}

const char* codecModelName(CodecModel model) {
    return model == CodecModel::kLossless ? "lossless" : "stream";
}

bool hasLosslessCodec(const WorkloadTrace& trace) {
    if (trace.frames.empty())
        return false;
    for (const WorkloadFrame& f : trace.frames) {
        if (f.bits_per_pixel_lossless.size() != trace.header.scales.size() ||
            f.static_split.bg_bytes_lossless < 0.0)
            return false;
    }
    return true;
}

Status applyCodecModel(WorkloadTrace& trace, CodecModel model) {
    if (model == CodecModel::kStream)
        return Status::success();
    if (!hasLosslessCodec(trace))
        return makeError(
            fmt::format("workload '{}' has no lossless codec measurements (bpp_lossless, "
                        "static.bg_bytes_lossless); record it again with qvr trace record, or use "
                        "--codec-model stream",
                        trace.header.name));
    for (WorkloadFrame& f : trace.frames) {
        f.bits_per_pixel = f.bits_per_pixel_lossless;
        f.static_split.bg_bytes = f.static_split.bg_bytes_lossless;
    }
    return Status::success();
}

Status validateTrace(const WorkloadTrace& trace) {
    if (auto st = validateHeader(trace.header); !st)
        return st;
    if (trace.frames.size() > static_cast<size_t>(kMaxTraceFrames))
        return makeError(fmt::format("more than {} frames", kMaxTraceFrames));
    double last_time = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < trace.frames.size(); ++i) {
        if (auto st = validateFrame(trace.header, trace.frames[i], last_time); !st)
            return makeError(fmt::format("frame {}: {}", i, st.error()));
        last_time = trace.frames[i].time_ms;
    }
    return Status::success();
}

}  // namespace qvr
