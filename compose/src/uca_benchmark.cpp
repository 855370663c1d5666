// `qvr bench uca`'s measurement: medians of UCA, the two-pass reference and the OpenCV
// anchor interleaved in one run, the copy-bandwidth floor for UCA's bytes, and image quality.
#include "qvr/compose/uca_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "qvr/compose/opencv_two_pass.h"
#include "qvr/compose/test_pattern.h"
#include "qvr/foveation/layer_plan.h"
#include "uca_kernel.h"

namespace qvr {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double minimum(const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
}

struct CopyBandwidth {
    double median_gbps = 0.0;
    double best_gbps = 0.0;
};

// Read + write bandwidth of a copy far larger than the caches, on the benchmark's threads.
CopyBandwidth measureCopyGbps(int threads) {
    constexpr size_t kBytes = size_t{256} << 20;
    std::vector<uint8_t> src(kBytes, 1), dst(kBytes, 0);
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    const int chunks = std::max(1, arena.max_concurrency()) * 8;
    const size_t chunk = kBytes / static_cast<size_t>(chunks);
    std::vector<double> ms;
    for (int rep = 0; rep < 7; ++rep) {
        const auto t0 = Clock::now();
        arena.execute([&] {
            tbb::parallel_for(0, chunks, [&](int c) {
                std::memcpy(dst.data() + static_cast<size_t>(c) * chunk,
                            src.data() + static_cast<size_t>(c) * chunk, chunk);
            });
        });
        ms.push_back(msSince(t0));
    }
    const double moved = 2.0 * static_cast<double>(kBytes);
    return {moved / (median(ms) * 1e6), moved / (minimum(ms) * 1e6)};
}

}  // namespace

Expected<UcaBenchResult> runUcaBenchmark(const UcaBenchOptions& o) {
    if (o.iterations < 1)
        return makeError("bench uca: --iterations must be at least 1");
    UcaBenchResult res;
    res.threads = o.threads;
    res.simd_target = detail::ucaSimdTarget();
    const LayerPlanner planner(o.profile);
    const LayerPlan plan = planner.plan(o.gaze, o.e1_deg);
    Pose render_pose;
    Pose display_pose;
    display_pose.orientation = quatFromEulerDeg(o.pose_change);
    res.pose_change_deg = angleBetweenDeg(render_pose.orientation, display_pose.orientation);
    const ImageRgba8 full = renderTestPattern(o.profile.width_px, o.profile.height_px);
    const LayerFrame frame = makeTestPatternFrame(o.profile, plan, render_pose, 1, full);

    ComposeOptions copts;
    copts.threads = o.threads;
    Compositor uca(o.profile, copts);
    std::array<ImageRgba8, 2> uca_out, two_pass_out, opencv_out, scalar_out;
    // Warm-up: first-touch of every buffer, thread start-up.
    if (auto r = uca.compose(frame, display_pose, uca_out); !r)
        return makeError(r.error());
    if (auto r = uca.composeTwoPass(frame, display_pose, two_pass_out); !r)
        return makeError(r.error());
#if defined(QVR_COMPOSE_HAVE_OPENCV)
    std::unique_ptr<OpenCvTwoPass> anchor;
    if (o.opencv) {
        anchor = std::make_unique<OpenCvTwoPass>(o.profile, copts);
        if (Status st = anchor->run(frame, display_pose, opencv_out); !st)
            return makeError(st.error());
    }
#endif
    std::vector<double> uca_ms, two_pass_ms, opencv_ms, scalar_ms;
    // Interleaved, so that all paths see the same machine; the OpenCV anchor first and UCA
    // last, after the two-pass run: OpenCV's own worker pool keeps spinning for a while after
    // its calls and, run just before UCA, took a core from it (+0.4 ms a frame).
    for (int i = 0; i < o.iterations; ++i) {
#if defined(QVR_COMPOSE_HAVE_OPENCV)
        if (anchor) {
            const auto t_cv = Clock::now();
            if (Status st = anchor->run(frame, display_pose, opencv_out); !st)
                return makeError(st.error());
            opencv_ms.push_back(msSince(t_cv));
        }
#endif
        auto t0 = Clock::now();
        if (auto r2 = uca.composeTwoPass(frame, display_pose, two_pass_out); !r2)
            return makeError(r2.error());
        two_pass_ms.push_back(msSince(t0));
        t0 = Clock::now();
        auto r = uca.compose(frame, display_pose, uca_out);
        uca_ms.push_back(msSince(t0));
        if (!r)
            return makeError(r.error());
        res.tiles = r->tiles;
    }
    // The scalar twin is an order of magnitude slower; a few runs give its median.
    uca.setSimd(false);
    for (int i = 0; i < std::min(o.iterations, 3); ++i) {
        const auto t0 = Clock::now();
        if (auto r = uca.compose(frame, display_pose, scalar_out); !r)
            return makeError(r.error());
        scalar_ms.push_back(msSince(t0));
    }
    uca.setSimd(true);
    res.uca_ms = median(uca_ms);
    res.two_pass_ms = median(two_pass_ms);
    res.uca_scalar_ms = median(scalar_ms);
    res.uca_min_ms = minimum(uca_ms);
    res.two_pass_min_ms = minimum(two_pass_ms);
    if (!opencv_ms.empty())
        res.opencv_two_pass_min_ms = minimum(opencv_ms);
    if (!opencv_ms.empty())
        res.opencv_two_pass_ms = median(opencv_ms);

    double bytes = 0.0;
    for (const auto& e : frame.eyes) {
        bytes +=
            static_cast<double>(e.fovea.sizeBytes() + e.middle.sizeBytes() + e.outer.sizeBytes());
    }
    for (const auto& img : uca_out)
        bytes += static_cast<double>(img.sizeBytes());
    res.uca_bytes = bytes;
    const CopyBandwidth copy = measureCopyGbps(o.threads);
    res.copy_gbps = copy.median_gbps;
    res.bandwidth_floor_ms = bytes / (copy.median_gbps * 1e6);
    res.bandwidth_floor_min_ms = bytes / (copy.best_gbps * 1e6);

    if (o.quality) {
        // Each pipeline's left eye against one reference image.
        auto against = [&](const ImageRgbD& reference, QualityReport& uca_q,
                           QualityReport& two_pass_q, std::optional<QualityReport>& opencv_q) {
            uca_q =
                measureQuality(o.profile, plan, render_pose, display_pose, uca_out[0], reference);
            two_pass_q = measureQuality(o.profile, plan, render_pose, display_pose, two_pass_out[0],
                                        reference);
            if (!opencv_ms.empty())
                opencv_q = measureQuality(o.profile, plan, render_pose, display_pose, opencv_out[0],
                                          reference);
        };
        against(groundTruthWarp(o.profile, full, render_pose, display_pose), res.uca_quality,
                res.two_pass_quality, res.opencv_quality);
        against(layerReferenceWarp(o.profile, frame, 0, display_pose), res.uca_vs_layers,
                res.two_pass_vs_layers, res.opencv_vs_layers);
    }
    return res;
}

}  // namespace qvr
