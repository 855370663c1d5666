// The runtime pipeline model (sim/runtime_model.h) against closed forms: with costs that do not
// depend on the frame, a design with one bottleneck stage runs at that stage's rate (rounded to
// vsync slots where the headset waits for them), two frames in flight overlap the headset's and
// the server's work exactly as far as the shorter stage allows, and a frame whose layers arrive
// later than the wait limit is reused. The closed forms rounded to vsync slots block the headset
// until its slot (RuntimeSimConfig::wait_for_vsync); the runtime's queued scan-out has its own.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>

#include "qvr/foveation/layer_plan.h"
#include "qvr/sim/network.h"
#include "qvr/sim/runtime_model.h"

namespace qvr {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

WorkloadTrace flatTrace(int frames) {
    WorkloadTrace t;
    t.header.name = "flat";
    t.header.profile = defaultHmdProfile();
    t.header.profile.width_px = 320;
    t.header.profile.height_px = 360;
    t.header.ring_deg = 1.0;
    t.header.rings = 120;
    t.header.scales = {1, 2, 4, 8, 16, 32};
    for (int i = 0; i < frames; ++i) {
        WorkloadFrame f;
        f.index = i;
        f.time_ms = 1000.0 * i / 90.0;
        f.triangles_per_ring.assign(120, 100.0);
        f.pixels_per_ring.assign(120, 1000.0);
        f.bits_per_pixel.assign(6, 0.1);
        t.frames.push_back(f);
    }
    return t;
}

// Costs that are the same for every frame: only the base terms.
RuntimeCosts flatCosts(double fovea_pass_ms, double uca_ms, double server_layer_ms) {
    RuntimeCosts c;
    c.decision = {0, 0, 0};
    c.fovea = {fovea_pass_ms, 0, 0};
    c.decode = {0, 0, 0};
    c.uca = {uca_ms, 0, 0};
    c.frame_overhead_ms = 0.0;
    c.server_render = {server_layer_ms, 0, 0};
    c.encode = {0, 0, 0};
    c.server_frame_ms = 0.0;
    c.link_delay_ms = 0.0;
    return c;
}

// ffr (a 5° fovea) over `frames` frames with these costs.
RuntimeSimConfig ffrConfig(const RuntimeCosts& costs, int frames) {
    RuntimeSimConfig cfg;
    cfg.design = Design::Ffr;
    cfg.costs = costs;
    cfg.frames = frames;
    return cfg;
}

// A fovea law of 1 ms per million fragments and nothing else (a 1 ms UCA), charging 2.5
// fragments a pixel where none are known.
RuntimeCosts fragmentLaw() {
    RuntimeCosts c = flatCosts(0.0, 1.0, 0.0);
    c.fovea = {};
    c.fovea.ms_per_mfrag = 1.0;
    c.fovea.frag_per_px = 2.5;
    return c;
}

// A link so fast its transfers take no measurable time.
NoisyLink fastLink() {
    return NoisyLink("fast", 1e15, 1.0, kInf, {0, 0}, 1);
}

const double kSlotMs = 1000.0 / 90.0;

double slots(double ms) {
    return std::ceil(ms / kSlotMs - 1e-9) * kSlotMs;
}

RuntimeRunResult run(Design d, const RuntimeCosts& costs, int depth, int frames = 60,
                     double wait_limit_ms = 250.0, bool wait_for_vsync = true,
                     double headset_share = 1.0) {
    const WorkloadTrace trace = flatTrace(frames);
    RuntimeSimConfig cfg;
    cfg.design = d;
    cfg.costs = costs;
    cfg.pipeline_depth = depth;
    cfg.frames = frames;
    cfg.wait_limit_ms = wait_limit_ms;
    cfg.wait_for_vsync = wait_for_vsync;
    cfg.headset_share = headset_share;
    cfg.quota_period_ms = 10.0;
    NoisyLink link = fastLink();
    return simulateRuntime(trace, cfg, link);
}

TEST(RuntimeModel, LocalRunsAtItsRenderPlusUcaRoundedToVsync) {
    // Two full-frame passes of 30 ms and 5 ms of UCA: 65 ms a frame on the headset's core, then
    // the next vsync slot.
    const RuntimeRunResult r = run(Design::Local, flatCosts(30.0, 5.0, 0.0), 2);
    EXPECT_NEAR(r.summary.fps_mean, 1000.0 / slots(65.0), 1e-6);
    EXPECT_NEAR(r.summary.mtp_ms_mean, 65.0, 1e-6);
    EXPECT_EQ(r.summary.frames_reused, 0);
    EXPECT_EQ(r.summary.bytes_per_frame_mean, 0.0);
    for (const RuntimeFrame& f : r.frames)
        EXPECT_NEAR(std::fmod(f.display_ms + 1e-9, kSlotMs), 0.0, 1e-6);
}

TEST(RuntimeModel, TheMiddleAndOuterLayersTakeTheirOwnBitsLaw) {
    // ffr at 5°: every frame sends both eyes' middle layer at its law and outer layer at its own
    // (a calibration measures the outer at ~0.6× the middle's bits per pixel at one scale).
    RuntimeCosts c = flatCosts(1.0, 1.0, 1.0);
    c.bits_per_px_at_1 = 0.4;
    c.bits_scale_exponent = 0.3;
    c.bits_outer_per_px_at_1 = 0.1;
    c.bits_outer_scale_exponent = 0.5;
    const WorkloadTrace trace = flatTrace(20);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(Gaze{}, 5.0);
    ASSERT_GT(plan.middle_pixels, 0);
    ASSERT_GT(plan.outer_pixels, 0);
    const double expected = 2.0 *
                            (double(plan.middle_pixels) * 0.4 * std::pow(plan.s1, 0.3) +
                             double(plan.outer_pixels) * 0.1 * std::pow(plan.s2, 0.5)) /
                            8.0;
    const RuntimeRunResult r = run(Design::Ffr, c, 2, 20);
    EXPECT_NEAR(r.summary.bytes_per_frame_mean, expected, 1e-6 * expected);
    // Without an outer law the outer takes the middle's.
    c.bits_outer_per_px_at_1 = 0.0;
    const double one_law = 2.0 *
                           (double(plan.middle_pixels) * 0.4 * std::pow(plan.s1, 0.3) +
                            double(plan.outer_pixels) * 0.4 * std::pow(plan.s2, 0.3)) /
                           8.0;
    EXPECT_NEAR(run(Design::Ffr, c, 2, 20).summary.bytes_per_frame_mean, one_law, 1e-6 * one_law);
}

TEST(RuntimeModel, AFrameTheCalibrationCodedTakesItsOwnBitsOverTheLaw) {
    // The calibration's frame-by-frame bits (calibration version 15): frame k's middle and
    // outer layers spend the law times the calibration's factors for its frame k, but only
    // where frame k's head pose is the one the calibration coded (its content key); anywhere
    // else, and past the frames it measured, the law alone.
    RuntimeCosts c = flatCosts(1.0, 1.0, 1.0);
    c.bits_per_px_at_1 = 0.4;
    c.bits_outer_per_px_at_1 = 0.1;
    const double key = double(frameContentKey(Pose{}));  // every flat frame's head pose
    Pose moved;
    moved.position_m.x = 0.5f;
    ASSERT_NE(frameContentKey(moved), frameContentKey(Pose{}));
    c.bits_frame_key = {0.0, key, double(frameContentKey(moved)), key};
    c.bits_frame_middle = {5.0, 1.5, 2.0, 1.0};
    c.bits_frame_outer = {5.0, 0.5, 2.0, 3.0};
    const WorkloadTrace trace = flatTrace(8);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(Gaze{}, 5.0);
    const double middle = 2.0 * double(plan.middle_pixels) * 0.4 / 8.0;  // both eyes; γ = 0
    const double outer = 2.0 * double(plan.outer_pixels) * 0.1 / 8.0;
    const RuntimeRunResult r = run(Design::Ffr, c, 2, 8);
    ASSERT_EQ(r.frames.size(), 8u);
    for (const RuntimeFrame& f : r.frames) {
        const double want = f.index == 1   ? 1.5 * middle + 0.5 * outer
                            : f.index == 3 ? middle + 3.0 * outer
                                           : middle + outer;
        EXPECT_NEAR(f.bytes, want, 1e-6 * want) << "frame " << f.index;
    }
    // remote's whole frame keeps its own measured bits per pixel.
    c.bits_full_frame_per_px = 0.15;
    const double eye_px =
        double(trace.header.profile.width_px) * double(trace.header.profile.height_px);
    for (const RuntimeFrame& f : run(Design::Remote, c, 2, 8).frames)
        EXPECT_NEAR(f.bytes, 2.0 * eye_px * 0.15 / 8.0, 1e-6 * eye_px) << "frame " << f.index;
}

TEST(RuntimeModel, RemotesWholeFrameTakesItsOwnMeasuredBitsPerPixel) {
    // remote sends one layer per eye at scale 1: its measured bits per pixel when the
    // calibration has it, else the layers' law at scale 1.
    RuntimeCosts c = flatCosts(1.0, 1.0, 1.0);
    c.bits_per_px_at_1 = 0.4;
    c.bits_scale_exponent = 0.3;
    c.bits_full_frame_per_px = 0.15;
    const WorkloadTrace trace = flatTrace(20);
    const double eye_px =
        double(trace.header.profile.width_px) * double(trace.header.profile.height_px);
    const double own = 2.0 * eye_px * 0.15 / 8.0;
    EXPECT_NEAR(run(Design::Remote, c, 2, 20).summary.bytes_per_frame_mean, own, 1e-6 * own);
    c.bits_full_frame_per_px = 0.0;
    const double law = 2.0 * eye_px * 0.4 / 8.0;
    EXPECT_NEAR(run(Design::Remote, c, 2, 20).summary.bytes_per_frame_mean, law, 1e-6 * law);
}

// The canvas model (calibration version 7): a key frame at each stream's first frame and every
// keyint_frames-th, the padding of a canvas larger than the snug one, an IDR when a layer outgrows
// its canvas.
RuntimeCosts canvasCosts() {
    RuntimeCosts c = flatCosts(1.0, 1.0, 1.0);
    c.bits_per_px_at_1 = 0.4;
    c.keyint_frames = 10;
    c.keyframe_bits_ratio = 6.0;
    c.keyframe_outer_bits_ratio = 4.0;
    c.keyframe_periodic_bits_ratio = 3.0;
    c.padding_bits_ratio = 0.5;
    return c;
}

TEST(RuntimeModel, EveryStreamSendsAKeyFrameFirstAndEveryKeyintFrames) {
    // ffr at 5°: the layers never change size, so the canvas is the snug one and only the
    // IDRs differ from the P-frames: each new encoder's first (frame 0: 6× the middle's P-frame,
    // 4× the outer's) and the periodic ones (frames 10, 20: 3×).
    const RuntimeCosts c = canvasCosts();
    const WorkloadTrace trace = flatTrace(30);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(Gaze{}, 5.0);
    const double middle = 2.0 * double(plan.middle_pixels) * 0.4 / 8.0;  // both eyes; γ = 0
    const double outer = 2.0 * double(plan.outer_pixels) * 0.4 / 8.0;
    const RuntimeRunResult r = run(Design::Ffr, c, 2, 30);
    ASSERT_EQ(r.frames.size(), 30u);
    for (const RuntimeFrame& f : r.frames) {
        const double want = f.index == 0        ? 6.0 * middle + 4.0 * outer
                            : f.index % 10 == 0 ? 3.0 * (middle + outer)
                                                : middle + outer;
        EXPECT_NEAR(f.bytes, want, 1e-6 * want) << "frame " << f.index;
    }
    // Without a key-frame ratio every frame is the P-frame (calibrations before version 7).
    RuntimeCosts off = c;
    off.keyframe_bits_ratio = 0.0;
    for (const RuntimeFrame& f : run(Design::Ffr, off, 2, 30).frames)
        EXPECT_NEAR(f.bytes, middle + outer, 1e-6 * (middle + outer));
}

TEST(RuntimeModel, APaddedCanvasCostsItsPaddingAndOutgrowingItAKeyFrame) {
    RuntimeCosts c = canvasCosts();
    c.keyint_frames = 0;
    StreamCodecModel m(c);
    // 200×100: the snug canvas is 224×112 (+10%, to 16). The first frame is its IDR.
    EXPECT_NEAR(m.bytes(0, 200, 100, 1000.0), 6000.0, 1e-9);
    EXPECT_TRUE(m.lastWasKey());
    EXPECT_NEAR(m.bytes(0, 200, 100, 1000.0), 1000.0, 1e-9);
    EXPECT_FALSE(m.lastWasKey());
    // 150×80 covers 0.48 of the canvas: it stays 224×112 (for 30 frames), whose snug one would
    // be 176×96: each extra pixel costs half a layer pixel's bits.
    const double extra = 224.0 * 112.0 / (176.0 * 96.0) - 1.0;
    EXPECT_NEAR(m.bytes(0, 150, 80, 1000.0), 1000.0 * (1.0 + 0.5 * extra), 1e-9);
    EXPECT_FALSE(m.lastWasKey());
    EXPECT_NEAR(m.lastCanvasPx(), 224.0 * 112.0, 1e-9);  // the codec's work: the canvas
    // The other streams have encoders of their own: their first frames are IDRs (outer: 4×).
    EXPECT_NEAR(m.bytes(1, 150, 80, 1000.0), 4000.0, 1e-9);
    // Outgrowing the canvas reopens the encoder: an IDR of the new snug canvas.
    EXPECT_NEAR(m.bytes(0, 230, 100, 1000.0), 6000.0, 1e-9);
    EXPECT_TRUE(m.lastWasKey());
    EXPECT_NEAR(m.bytes(0, 230, 100, 1000.0), 1000.0, 1e-9);
}

TEST(RuntimeModel, TheEncodeAndDecodeLawsChargeTheWholeCanvas) {
    // ffr at 5°: each of the four streams codes into its snug canvas, the layer plus 10% a side
    // rounded up to 16 px, and the calibration times encode and decode against that canvas. An
    // encode law of 10 ms per Mpx and a decode law of 4 ms per Mpx then charge every frame
    // 10 (and 4) ms per Mpx of the canvases, not of the layers.
    RuntimeCosts c = canvasCosts();
    c.encode = {0, 10.0, 0};
    c.decode = {0, 4.0, 0};
    const WorkloadTrace trace = flatTrace(20);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(Gaze{}, 5.0);
    auto snug = [](int v) { return double((int(std::ceil(v * 1.1)) + 15) / 16 * 16); };
    double canvas_px = 0.0, layer_px = 0.0;
    for (const EyeLayers& e : plan.eyes)
        for (const LayerRect* rect : {&e.middle, &e.outer}) {
            ASSERT_FALSE(rect->empty());
            canvas_px += snug(rect->width_px) * snug(rect->height_px);
            layer_px += double(rect->pixels());
        }
    ASSERT_GT(canvas_px, 1.1 * layer_px);  // the difference is worth a test
    const RuntimeRunResult r = run(Design::Ffr, c, 1, 20);
    ASSERT_EQ(r.frames.size(), 20u);
    for (const RuntimeFrame& f : r.frames)
        EXPECT_NEAR(f.server_encode_ms, 10.0 * canvas_px / 1e6, 1e-9) << "frame " << f.index;
    // The headset: the fovea pass (1 ms) twice, UCA (1 ms), the four decodes.
    EXPECT_NEAR(r.summary.headset_busy_ms_mean, 3.0 + 4.0 * canvas_px / 1e6, 1e-6);
    // remote's whole frame (320×360 an eye here) in its canvas, at the encode's whole-frame
    // scale, as the calibration measures it on whole frames.
    c.encode.full_frame_scale = 0.5;
    const double whole_px = 2.0 * snug(320) * snug(360);
    for (const RuntimeFrame& f : run(Design::Remote, c, 1, 20).frames)
        EXPECT_NEAR(f.server_encode_ms, 0.5 * 10.0 * whole_px / 1e6, 1e-9) << "frame " << f.index;
}

TEST(RuntimeModel, ServerBoundRemoteRunsAtTheServersRate) {
    // Two full-frame layers of 100 ms on the server: 200 ms a frame. With two frames in flight
    // the server never idles, so scan-outs follow it exactly; with one it idles while the headset
    // composes and waits for vsync.
    const RuntimeRunResult two = run(Design::Remote, flatCosts(0.0, 1.0, 100.0), 2);
    EXPECT_NEAR(two.summary.fps_mean, 1000.0 / 200.0, 1e-6);
    EXPECT_EQ(two.summary.frames_reused, 0);
    EXPECT_GT(two.summary.bytes_per_frame_mean, 0.0);
    const RuntimeRunResult one = run(Design::Remote, flatCosts(0.0, 1.0, 100.0), 1);
    EXPECT_NEAR(one.summary.fps_mean, 1000.0 / slots(201.0), 1e-6);
    EXPECT_NEAR(one.summary.mtp_ms_mean, 201.0, 1e-6);
}

TEST(RuntimeModel, AtSpeedScalesEachSidesTimesAndNothingElse) {
    // The machine 1.5x as slow on the server's side and 0.8x on the headset's: a server-bound
    // remote at depth 2 runs at the scaled server's rate (2 × 100 ms × 1.5), a headset-bound
    // local at its scaled passes ((2 × 30 ms + 5 ms UCA) × 0.8), rounded to vsync.
    const RuntimeRunResult remote =
        run(Design::Remote, flatCosts(0.0, 1.0, 100.0).atSpeed(0.8, 1.5), 2, 60, 1000.0);
    EXPECT_NEAR(remote.summary.fps_mean, 1000.0 / 300.0, 1e-6);
    EXPECT_EQ(remote.summary.frames_reused, 0);  // 300 ms a frame, under the 1 s wait limit
    const RuntimeCosts c = flatCosts(30.0, 5.0, 100.0);
    const RuntimeRunResult local = run(Design::Local, c.atSpeed(0.8, 1.5), 2);
    EXPECT_NEAR(local.summary.fps_mean, 1000.0 / slots(0.8 * 65.0), 1e-6);
    EXPECT_NEAR(local.summary.mtp_ms_mean, 0.8 * 65.0, 1e-6);
    // Every time term on its side; the bits, the link and the co-running ratios stay.
    RuntimeCosts full = c;
    full.decision = {0.5, 0, 0.04};
    full.decode = {0.3, 4.0, 0};
    full.fovea.power_coef_ms = 2.0;
    full.frame_overhead_ms = 0.5;
    full.scanout_record_ms = 1.0;
    full.encode = {0.5, 12.0, 0};
    full.server_frame_ms = 2.0;
    full.link_delay_ms = 7.0;
    full.bits_per_px_at_1 = 0.3;
    full.corun_server_slowdown = 1.1;
    const RuntimeCosts s = full.atSpeed(2.0, 3.0);
    EXPECT_DOUBLE_EQ(s.decision.ms_per_ktri, 0.08);
    EXPECT_DOUBLE_EQ(s.decode.ms_per_mpx, 8.0);
    EXPECT_DOUBLE_EQ(s.fovea.power_coef_ms, 4.0);
    EXPECT_DOUBLE_EQ(s.uca.base_ms, 10.0);
    EXPECT_DOUBLE_EQ(s.frame_overhead_ms, 1.0);
    EXPECT_DOUBLE_EQ(s.scanout_record_ms, 2.0);
    EXPECT_DOUBLE_EQ(s.server_render.base_ms, 300.0);
    EXPECT_DOUBLE_EQ(s.encode.ms_per_mpx, 36.0);
    EXPECT_DOUBLE_EQ(s.server_frame_ms, 6.0);
    EXPECT_DOUBLE_EQ(s.link_delay_ms, 7.0);
    EXPECT_DOUBLE_EQ(s.bits_per_px_at_1, 0.3);
    EXPECT_DOUBLE_EQ(s.corun_server_slowdown, 1.1);
    EXPECT_DOUBLE_EQ(s.fovea.px_exponent, full.fovea.px_exponent);
}

TEST(RuntimeModel, TwoFramesInFlightOverlapAsFarAsTheShorterStageAllows) {
    // Foveated: the headset renders two 20 ms fovea passes and 5 ms of UCA (45 ms), the server
    // four 15 ms layers (60 ms). One frame in flight overlaps only the fovea with the server:
    // max(40, 60) + 5 ms, then vsync. Two frames overlap everything: the longer stage sets the
    // pace.
    const RuntimeCosts server_bound = flatCosts(20.0, 5.0, 15.0);
    const RuntimeRunResult one = run(Design::Ffr, server_bound, 1);
    EXPECT_NEAR(one.summary.fps_mean, 1000.0 / slots(60.0 + 5.0), 1e-6);
    const RuntimeRunResult two = run(Design::Ffr, server_bound, 2, 120);
    // After the first frames (the server starts with both requests queued), every scan-out
    // follows the server by its 60 ms (each rounded up to a vsync slot, which the mean over n
    // intervals sees as at most one slot / n).
    const double intervals = double(two.frames.size() - 21);
    const double span = two.frames.back().display_ms - two.frames[20].display_ms;
    EXPECT_NEAR(span / intervals, 60.0, kSlotMs / intervals);
    for (size_t k = 21; k < two.frames.size(); ++k)
        EXPECT_NEAR(two.frames[k].remote_done_ms - two.frames[k - 1].remote_done_ms, 60.0, 1e-6);
    EXPECT_EQ(two.summary.frames_reused, 0);

    // Headset-bound (two 40 ms passes + 5 ms UCA = 85 ms against the server's 60 ms): the
    // headset's own time, rounded to its vsync slot, sets the pace; depth 1 pays both in turn.
    const RuntimeCosts headset_bound = flatCosts(40.0, 5.0, 15.0);
    const RuntimeRunResult hb2 = run(Design::Ffr, headset_bound, 2);
    EXPECT_NEAR(hb2.summary.fps_mean, 1000.0 / slots(85.0), 1e-6);
    const RuntimeRunResult hb1 = run(Design::Ffr, headset_bound, 1);
    EXPECT_NEAR(hb1.summary.fps_mean, 1000.0 / slots(85.0), 1e-6);
    EXPECT_NEAR(hb1.summary.headset_busy_ms_mean, 85.0, 1e-6);
}

TEST(RuntimeModel, AFrameDecodedBeforeItsWaitKeepsItsRemoteTime) {
    // Headset-bound with two frames in flight: the server's four 5 ms layers (20 ms) are done
    // long before the headset's 85 ms frame ends, and the streams are decoded at the next pump,
    // before the frame's own wait. Its remote time still runs from when the server could start
    // on it (its request, the server idle) to its last packet: 20 ms, as the runtime measures
    // it. The model took the start from the newest completed frame, which by then was this very
    // frame, and reported 0 ms: LIWC's server fit then learned that the server costs nothing.
    const RuntimeRunResult r = run(Design::Ffr, flatCosts(40.0, 5.0, 5.0), 2);
    ASSERT_GT(r.frames.size(), 30u);
    for (size_t k = 10; k < r.frames.size(); ++k) {
        ASSERT_TRUE(r.frames[k].requested);
        EXPECT_NEAR(r.frames[k].t_remote_ms, 20.0, 1e-6) << "frame " << k;
    }
}

TEST(RuntimeModel, CoRunEndSlowsOnlyWhereTheOtherSideIsBusy) {
    const std::vector<BusySpan> other{{10.0, 20.0}, {30.0, 40.0}};
    // Nothing of the other side's in the way, or no slowdown: the work's own length.
    EXPECT_DOUBLE_EQ(coRunEnd(0.0, 5.0, other, 2.0), 5.0);
    EXPECT_DOUBLE_EQ(coRunEnd(40.0, 5.0, other, 2.0), 45.0);
    EXPECT_DOUBLE_EQ(coRunEnd(12.0, 5.0, other, 1.0), 17.0);
    EXPECT_DOUBLE_EQ(coRunEnd(12.0, 0.0, other, 2.0), 12.0);
    // Inside a span: twice as long at a slowdown of 2.
    EXPECT_DOUBLE_EQ(coRunEnd(12.0, 3.0, other, 2.0), 18.0);
    // 5 ms alone to 10, 5 ms of work in 10 ms shared to 20, 2 ms alone to 22.
    EXPECT_DOUBLE_EQ(coRunEnd(5.0, 12.0, other, 2.0), 22.0);
    // Across both spans: 10 alone, 5 in [10, 20], 10 alone, 5 in [30, 40], 3 alone.
    EXPECT_DOUBLE_EQ(coRunEnd(0.0, 33.0, other, 2.0), 43.0);
}

TEST(RuntimeModel, CoRunningSlowsWhatOverlapsAndNothingElse) {
    // One frame in flight, ffr: the server's four 15 ms layers (60 ms) start with the headset's
    // two 20 ms fovea passes (40 ms). At a slowdown of 1.25 both run at 0.8 of their pace while
    // both work: the fovea ends at 50 ms, by when the server has done 40 ms of its 60; its last
    // 20 ms run alone (to 70 ms); then 5 ms of UCA with the server idle: 75 ms, then vsync.
    RuntimeCosts c = flatCosts(20.0, 5.0, 15.0);
    c.corun_slowdown = 1.25;
    const RuntimeRunResult one = run(Design::Ffr, c, 1);
    EXPECT_NEAR(one.summary.fps_mean, 1000.0 / slots(75.0), 1e-6);
    // The passes approach the fixed point from both sides; after them it is within 0.1 ms.
    for (size_t k = 10; k < one.frames.size(); ++k) {
        EXPECT_NEAR(one.frames[k].t_local_ms, 50.0, 0.1) << k;
        EXPECT_NEAR(one.frames[k].uca_end_ms - one.frames[k].pose_ms, 75.0, 0.1) << k;
    }
    // local has no server to run beside: unchanged.
    RuntimeCosts l = flatCosts(30.0, 5.0, 0.0);
    const double alone = run(Design::Local, l, 2).summary.fps_mean;
    l.corun_slowdown = 2.0;
    EXPECT_DOUBLE_EQ(run(Design::Local, l, 2).summary.fps_mean, alone);
}

TEST(RuntimeModel, EachSideSlowsByItsOwnCoRunningFactor) {
    // The same frame as above with a factor per side. The server slowed 1.25x beside the
    // headset, the headset not at all: the fovea ends at 40 ms; by then the server has done
    // 32 ms of its 60 at 0.8 of its pace, its last 28 run alone (to 68 ms); UCA: 73 ms.
    RuntimeCosts server_only = flatCosts(20.0, 5.0, 15.0);
    server_only.corun_headset_slowdown = 1.0;
    server_only.corun_server_slowdown = 1.25;
    const RuntimeRunResult s = run(Design::Ffr, server_only, 1);
    // The headset slowed 1.25x, the server not: the fovea's 40 ms take 50 beside the server's
    // 60 ms alone; UCA after the server: 65 ms.
    RuntimeCosts headset_only = flatCosts(20.0, 5.0, 15.0);
    headset_only.corun_headset_slowdown = 1.25;
    headset_only.corun_server_slowdown = 1.0;
    const RuntimeRunResult h = run(Design::Ffr, headset_only, 1);
    for (size_t k = 10; k < s.frames.size(); ++k) {
        EXPECT_NEAR(s.frames[k].t_local_ms, 40.0, 0.1) << k;
        EXPECT_NEAR(s.frames[k].uca_end_ms - s.frames[k].pose_ms, 73.0, 0.1) << k;
        EXPECT_NEAR(h.frames[k].t_local_ms, 50.0, 0.1) << k;
        EXPECT_NEAR(h.frames[k].uca_end_ms - h.frames[k].pose_ms, 65.0, 0.1) << k;
    }
    // A side's own factor stands in for the shared one; without one the shared one holds.
    RuntimeCosts shared = flatCosts(20.0, 5.0, 15.0);
    shared.corun_slowdown = 1.25;
    shared.corun_server_slowdown = 1.0;
    EXPECT_DOUBLE_EQ(shared.headsetCoRun(), 1.25);
    EXPECT_DOUBLE_EQ(shared.serverCoRun(), 1.0);
}

TEST(RuntimeModel, AFrameLaterThanTheWaitLimitIsReused) {
    // One frame in flight, server 2 × 120 ms = 240 ms: in time for a 250 ms limit...
    const RuntimeRunResult in_time = run(Design::Remote, flatCosts(0.0, 1.0, 120.0), 1, 30);
    EXPECT_EQ(in_time.summary.frames_reused, 0);
    // ...and every frame late for a 230 ms one: each is shown 230 ms after its request.
    const RuntimeRunResult late =
        run(Design::Remote, flatCosts(0.0, 1.0, 120.0), 1, 30, /*wait_limit_ms=*/230.0);
    EXPECT_EQ(late.summary.frames_reused, 30);
    EXPECT_NEAR(late.frames[0].uca_start_ms - late.frames[0].request_ms, 230.0, 1e-6);
}

TEST(RuntimeModel, ASilentServerCostsOneWaitLimitThenOneRefreshPerFrame) {
    // ffr against a server that needs 1 s per layer: the first frame waits the 250 ms limit
    // (nothing says the server is stalled yet); every later frame before the first stream
    // arrives that asked for layers waits one refresh, as the runtime's headset does once the
    // server has sent nothing for a whole limit (silent_server_frames); one the request window
    // withheld waits for nothing.
    const RuntimeRunResult r = run(Design::Ffr, flatCosts(1.0, 1.0, 1000.0), 1, 40);
    EXPECT_NEAR(r.frames[0].uca_start_ms - r.frames[0].local_end_ms, 250.0, 1e-6);
    int silent = 0, withheld = 0;
    for (size_t k = 1; k < r.frames.size() && r.frames[k].uca_start_ms < 1000.0; ++k) {
        const RuntimeFrame& f = r.frames[k];
        EXPECT_NEAR(f.uca_start_ms - f.local_end_ms, f.withheld ? 0.0 : kSlotMs, 1e-6) << k;
        EXPECT_TRUE(f.reused);
        silent += f.withheld ? 0 : 1;
        withheld += f.withheld ? 1 : 0;
    }
    EXPECT_GT(silent + withheld, 20);  // waiting the limit every time: 3 frames before 1 s
    EXPECT_GE(silent, 2);
}

TEST(RuntimeModel, AFramesBytesCountWhenTheyArriveAfterItWasShown) {
    // remote, one frame in flight, 400 ms per whole-frame layer: frame 0 is reused at the
    // 250 ms limit; frame 1, with the server silent for a whole limit, is shown a refresh later
    // and the runtime drops frame 0's pending entry. Frame 0's streams arrive at 400 and 800 ms,
    // after it was shown: both count as frame 0's bytes (what crossed the link for it), as with
    // 200 ms per layer, whose streams arrive while frame 0 and then frame 1 wait. 100 frames,
    // so the run (one refresh a frame after the first limit) outlasts the 800 ms.
    const double stream_bytes = 320.0 * 360.0 * 0.1 / 8.0;  // the trace's 0.1 bits per pixel
    const RuntimeRunResult late = run(Design::Remote, flatCosts(0.0, 1.0, 400.0), 1, 100);
    ASSERT_TRUE(late.frames[0].reused);
    ASSERT_LT(late.frames[1].uca_start_ms, 400.0);
    EXPECT_TRUE(late.frames[0].served);
    EXPECT_NEAR(late.frames[0].bytes, 2.0 * stream_bytes, 1e-6);
    const RuntimeRunResult in_wait = run(Design::Remote, flatCosts(0.0, 1.0, 200.0), 1, 10);
    ASSERT_TRUE(in_wait.frames[0].reused);
    EXPECT_NEAR(in_wait.frames[0].bytes, 2.0 * stream_bytes, 1e-6);
}

TEST(RuntimeModel, TheServersQueueKeepsTheNewestRequests) {
    // A server far slower than the wait limit with two frames in flight: the headset moves on
    // with reused frames; a request holds its place in the window (request_window.h) only for a
    // wait limit while nothing comes, so requests still pile up; the queue (2) drops the oldest.
    const RuntimeRunResult r = run(Design::Remote, flatCosts(0.0, 1.0, 400.0), 2, 40);
    EXPECT_GT(r.summary.requests_dropped, 0);
    EXPECT_GT(r.summary.requests_withheld, 0);
    int served = 0, requested = 0;
    for (const RuntimeFrame& f : r.frames) {
        served += f.served ? 1 : 0;
        requested += f.requested ? 1 : 0;
        EXPECT_NE(f.requested, f.withheld) << f.index;
    }
    EXPECT_EQ(requested, 40 - r.summary.requests_withheld);
    EXPECT_EQ(served + r.summary.requests_dropped, requested - 2 /* still queued at the end */);
    EXPECT_GT(r.summary.frames_reused, 0);
}

TEST(RuntimeModel, CostsScaleWithPixelsAndTriangles) {
    // The same design with a per-pixel fovea cost: a larger fixed fovea costs more.
    RuntimeCosts c = flatCosts(1.0, 1.0, 1.0);
    c.fovea.ms_per_mpx = 100.0;
    const WorkloadTrace trace = flatTrace(20);
    RuntimeSimConfig cfg = ffrConfig(c, 20);
    NoisyLink link = fastLink();
    cfg.fixed_e1_deg = 5.0;
    const RuntimeRunResult small = simulateRuntime(trace, cfg, link);
    cfg.fixed_e1_deg = 20.0;
    const RuntimeRunResult large = simulateRuntime(trace, cfg, link);
    EXPECT_NEAR(small.summary.e1_deg_mean, 5.0, 1e-9);
    EXPECT_NEAR(large.summary.e1_deg_mean, 20.0, 1e-9);
    // Closed form: two passes of 1 ms + 100 ms per Mpx of the plan's fovea.
    const LayerPlanner planner(trace.header.profile);
    for (const RuntimeRunResult* r : {&small, &large}) {
        const LayerPlan plan = planner.plan(trace.frames[0].gaze, r->summary.e1_deg_mean);
        const double px = double(plan.eyes[0].fovea.pixels() + plan.eyes[1].fovea.pixels());
        EXPECT_NEAR(r->frames[0].t_local_ms, 2.0 + 100.0 * px * 1e-6, 1e-9);
    }
    EXPECT_GT(large.summary.t_local_ms_mean, small.summary.t_local_ms_mean);
}

TEST(RuntimeModel, ServerLayersCostTheirTrianglesOverTheirScaleSquared) {
    // Only a per-triangle server cost: a frame costs Σ layers cone triangles / 2 / s², middle
    // over the cone to e2, outer over everything.
    RuntimeCosts c = flatCosts(1.0, 1.0, 0.0);
    c.server_render = {0.0, 0.0, 1.0};
    const WorkloadTrace trace = flatTrace(10);
    RuntimeSimConfig cfg = ffrConfig(c, 10);
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(trace.frames[0].gaze, 5.0);
    const WorkloadFrame& f = trace.frames[0];
    const double mid = sumWithinDeg(f.triangles_per_ring, 1.0, plan.e2_deg);
    const double all = sumTotal(f.triangles_per_ring);
    double expected = 0.0;
    for (const EyeLayers& e : plan.eyes) {
        if (!e.middle.empty())
            expected += serverLayerTriangles(mid, e.middle.scale) * 1e-3;
        if (!e.outer.empty())
            expected += serverLayerTriangles(all, e.outer.scale) * 1e-3;
    }
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(r.summary.server_busy_ms_mean, expected, 1e-9);
    EXPECT_NEAR(serverLayerTriangles(1000.0, 2.0), 125.0, 1e-12);
    EXPECT_NEAR(serverLayerTriangles(1000.0, 0.5), 500.0, 1e-12);  // scales below 1 count as 1
}

TEST(RuntimeModel, QueuedScanOutLetsTheHeadsetRunAtItsOwnRate) {
    // The runtime queues the composed image for its slot and goes on: a 65 ms local frame is
    // shown every 65 ms on average (each at the slot after it, so the span of n intervals is
    // 65·n within one slot), not every ⌈65 / slot⌉ slots as when it blocked.
    const int n = 60;
    const RuntimeRunResult r = run(Design::Local, flatCosts(30.0, 5.0, 0.0), 2, n, 250.0, false);
    const double intervals = double(n - 1);
    EXPECT_NEAR(1000.0 / r.summary.fps_mean, 65.0, kSlotMs / intervals);
    EXPECT_NEAR(r.summary.mtp_ms_mean, 65.0, 1e-6);
    for (size_t k = 1; k < r.frames.size(); ++k) {
        EXPECT_NEAR(r.frames[k].pose_ms - r.frames[k - 1].pose_ms, 65.0, 1e-6);
        EXPECT_NEAR(std::fmod(r.frames[k].display_ms + 1e-9, kSlotMs), 0.0, 1e-6);
    }
    // Faster than the display: one frame per slot, the headset sleeping only until the slot
    // before the previous frame's (its image then leaves the other buffer free), so each frame
    // starts one period before the previous one is shown and still takes 5 ms.
    const RuntimeRunResult fast = run(Design::Local, flatCosts(2.0, 1.0, 0.0), 2, n, 250.0, false);
    EXPECT_NEAR(fast.summary.fps_mean, 90.0, 1e-6);
    EXPECT_NEAR(fast.summary.mtp_ms_mean, 5.0, 1e-6);
    for (size_t k = 2; k < fast.frames.size(); ++k)
        EXPECT_NEAR(fast.frames[k].pose_ms, fast.frames[k - 1].display_ms - kSlotMs, 1e-6);
}

TEST(RuntimeModel, AQuotaThrottlesTheHeadsetOnlyOnceItsPeriodsBudgetIsSpent) {
    // 65 ms of CPU a frame, never idle, half of every 10 ms period: 5 ms run, 5 ms throttled, so
    // a frame every 130 ms (the same as a half-speed headset).
    const RuntimeRunResult busy =
        run(Design::Local, flatCosts(30.0, 5.0, 0.0), 2, 60, 250.0, false, 0.5);
    EXPECT_NEAR(1000.0 / busy.summary.fps_mean, 130.0, 130.0 / 59.0);
    // 3 ms a frame, shown at 90 Hz with the headset idle until its slot: no period holds more
    // than 5 ms of work, so nothing is throttled and a frame still takes 3 ms (a half-speed
    // headset would take 6).
    const RuntimeRunResult light =
        run(Design::Local, flatCosts(1.0, 1.0, 0.0), 2, 60, 250.0, true, 0.5);
    EXPECT_NEAR(light.summary.fps_mean, 90.0, 1e-6);
    EXPECT_NEAR(light.summary.mtp_ms_mean, 3.0, 1e-6);
    // No quota: the same as before.
    const RuntimeRunResult none =
        run(Design::Local, flatCosts(30.0, 5.0, 0.0), 2, 60, 250.0, false);
    EXPECT_NEAR(none.summary.mtp_ms_mean, 65.0, 1e-6);
}

TEST(RuntimeModel, RecordingTheDisplayVideoCostsEveryFrameItsCopyAfterTheFrameIsQueued) {
    // Local at 65 ms a frame with the video's 3 ms copy after each frame is queued: a frame every
    // 68 ms, its MTP still 65 ms (the copy comes after UCA), and the next frame's busy time 68.
    const int n = 60;
    RuntimeCosts c = flatCosts(30.0, 5.0, 0.0);
    c.scanout_record_ms = 3.0;
    const WorkloadTrace trace = flatTrace(n);
    RuntimeSimConfig cfg;
    cfg.design = Design::Local;
    cfg.costs = c;
    cfg.frames = n;
    cfg.record_scanout = true;
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    EXPECT_NEAR(1000.0 / r.summary.fps_mean, 68.0, kSlotMs / double(n - 1));
    EXPECT_NEAR(r.summary.mtp_ms_mean, 65.0, 1e-6);
    for (size_t k = 1; k < r.frames.size(); ++k) {
        EXPECT_NEAR(r.frames[k].pose_ms - r.frames[k - 1].pose_ms, 68.0, 1e-6);
        if (k >= 2) {
            EXPECT_NEAR(r.frames[k].headset_busy_ms, 68.0, 1e-6);
        }
    }
    // Not recording: the cost is not paid.
    cfg.record_scanout = false;
    NoisyLink link2 = fastLink();
    const RuntimeRunResult off = simulateRuntime(trace, cfg, link2);
    EXPECT_NEAR(1000.0 / off.summary.fps_mean, 65.0, kSlotMs / double(n - 1));
}

TEST(RuntimeModel, TRemoteRunsToTheLastPacketNotTheDecode) {
    // Remote, one frame in flight, two 100 ms layers, 3 ms per decode, an instant link: the last
    // packet arrives 200 ms after the request; its decode ends 3 ms later (the first stream was
    // decoded while the headset waited for the second).
    RuntimeCosts c = flatCosts(0.0, 1.0, 100.0);
    c.decode = {3.0, 0.0, 0.0};
    const WorkloadTrace trace = flatTrace(20);
    RuntimeSimConfig cfg;
    cfg.design = Design::Remote;
    cfg.costs = c;
    cfg.pipeline_depth = 1;
    cfg.frames = 20;
    NoisyLink link = fastLink();
    const RuntimeRunResult rx = simulateRuntime(trace, cfg, link);
    EXPECT_NEAR(rx.summary.t_remote_ms_mean, 200.0, 1e-6);
    cfg.t_remote_to_decode = true;
    NoisyLink link2 = fastLink();
    const RuntimeRunResult dec = simulateRuntime(trace, cfg, link2);
    EXPECT_NEAR(dec.summary.t_remote_ms_mean, 203.0, 1e-6);
    // Both show the frame after the decode: MTP = 200 + 3 + UCA 1.
    EXPECT_NEAR(rx.summary.mtp_ms_mean, 204.0, 1e-6);
}

TEST(RuntimeModel, LayersCostTheTrianglesTheCallerSaysTheyDraw) {
    // With a layer_triangles count (what the renderer submits: level of detail, holes), fovea
    // and server layers are charged on it, not on the trace's rings: per ktri costs only, a
    // count of 1000·(kind + 1) + 500·eye triangles per layer gives closed forms.
    RuntimeCosts c = flatCosts(0.0, 1.0, 0.0);
    c.fovea = {0.0, 0.0, 1.0};
    c.server_render = {0.0, 0.0, 2.0};
    const WorkloadTrace trace = flatTrace(10);
    RuntimeSimConfig cfg = ffrConfig(c, 10);
    int calls = 0;
    cfg.layer_triangles = [&](int64_t frame, const LayerPlan& plan, int eye, int kind) {
        ++calls;
        EXPECT_GE(frame, 0);
        EXPECT_LT(frame, 10);
        EXPECT_NEAR(plan.e1_deg, 5.0, 1e-9);
        return 1000.0 * (kind + 1) + 500.0 * eye;
    };
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    EXPECT_GT(calls, 0);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(trace.frames[0].gaze, 5.0);
    double fovea = 0.0, server = 0.0;
    for (int eye = 0; eye < 2; ++eye) {
        const EyeLayers& e = plan.eyes[static_cast<size_t>(eye)];
        if (!e.fovea.empty())
            fovea += 1.0 * (1.0 + 0.5 * eye);
        if (!e.middle.empty())
            server += 2.0 * (2.0 + 0.5 * eye);
        if (!e.outer.empty())
            server += 2.0 * (3.0 + 0.5 * eye);
    }
    EXPECT_GT(server, 0.0);
    EXPECT_NEAR(r.frames[3].t_local_ms, fovea, 1e-9);
    EXPECT_NEAR(r.summary.server_busy_ms_mean, server, 1e-9);
    // Remote's whole frame is the all-local plan's full view (kind 0) per eye.
    cfg.design = Design::Remote;
    cfg.layer_triangles = [](int64_t, const LayerPlan&, int eye, int kind) {
        EXPECT_EQ(kind, 0);
        return 1000.0 + 1000.0 * eye;
    };
    NoisyLink link2 = fastLink();
    const RuntimeRunResult rr = simulateRuntime(trace, cfg, link2);
    EXPECT_NEAR(rr.summary.server_busy_ms_mean, 2.0 * (1.0 + 2.0), 1e-9);
}

TEST(RuntimeModel, TheFoveaCostsTheFragmentsTheCallerSaysItShades) {
    // A fovea law of 1 ms per million fragments and nothing else: with a fovea_fragments count
    // of 1e6·(frame + 1)·(eye + 1) per eye, frame k's fovea takes 3·(k + 1) ms; where the count
    // is not known (< 0, here frame 4) its pixels at the calibration's 2.5 fragments a pixel.
    const RuntimeCosts c = fragmentLaw();
    const WorkloadTrace trace = flatTrace(10);
    RuntimeSimConfig cfg = ffrConfig(c, 10);
    cfg.fovea_fragments = [](int64_t frame, const LayerPlan& plan, int eye) {
        EXPECT_NEAR(plan.e1_deg, 5.0, 1e-9);
        return frame == 4 ? -1.0 : 1e6 * double(frame + 1) * double(eye + 1);
    };
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    for (int k : {1, 3, 7})
        EXPECT_NEAR(r.frames[size_t(k)].t_local_ms, 3.0 * (k + 1), 1e-9) << k;
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(trace.frames[4].gaze, 5.0);
    const double px = double(plan.eyes[0].fovea.pixels() + plan.eyes[1].fovea.pixels());
    EXPECT_NEAR(r.frames[4].t_local_ms, 2.5 * px * 1e-6, 1e-9);
    // Without a count at all, every frame is charged its pixels.
    cfg.fovea_fragments = nullptr;
    NoisyLink link2 = fastLink();
    EXPECT_NEAR(simulateRuntime(trace, cfg, link2).frames[7].t_local_ms, 2.5 * px * 1e-6, 1e-9);
}

TEST(RuntimeModel, TheServerCostsTheFragmentsTheCallerSaysItsLayersShade) {
    // A server law of 1 ms per million fragments and nothing else: with a server_fragments count
    // of 1e6·(stream + 1) per layer, every served ffr frame renders for 1 + 2 + 3 + 4 = 10 ms;
    // where the count is not known (< 0, frame 4) the layers' pixels at 2.5 fragments a pixel.
    RuntimeCosts c = flatCosts(0.0, 1.0, 0.0);
    c.server_render = {};
    c.server_render.ms_per_mfrag = 1.0;
    c.server_render.frag_per_px = 2.5;
    const WorkloadTrace trace = flatTrace(10);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(trace.frames[4].gaze, 5.0);
    double px = 0.0;
    for (const EyeLayers& e : plan.eyes)
        px += double(e.middle.pixels() + e.outer.pixels());
    RuntimeSimConfig cfg = ffrConfig(c, 10);
    std::set<int> streams;
    cfg.server_fragments = [&](int64_t frame, int stream, double pixels) {
        streams.insert(stream);
        EXPECT_GT(pixels, 0.0);
        return frame == 4 ? -1.0 : 1e6 * double(stream + 1);
    };
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    EXPECT_EQ(streams, (std::set<int>{0, 1, 2, 3}));
    for (int k : {1, 3, 7})
        EXPECT_NEAR(r.frames[size_t(k)].server_render_ms, 10.0, 1e-9) << k;
    EXPECT_NEAR(r.frames[4].server_render_ms, 2.5 * px * 1e-6, 1e-9);
    // Without counts every frame is charged its pixels.
    cfg.server_fragments = nullptr;
    NoisyLink link2 = fastLink();
    EXPECT_NEAR(simulateRuntime(trace, cfg, link2).frames[7].server_render_ms, 2.5 * px * 1e-6,
                1e-9);
}

TEST(RuntimeModel, WithoutTheCallersCountsTheFoveaCostsTheTracesRecordedFragments) {
    // The same law, no fovea_fragments: frames that recorded their fovea's fragments per pixel
    // (a qvr run's workload.jsonl, frag_px) are charged that many per fovea pixel, the others
    // the calibration's 2.5; a whole-frame pass (local) is never charged the fovea's overdraw.
    const RuntimeCosts c = fragmentLaw();
    WorkloadTrace trace = flatTrace(10);
    for (int k : {2, 6})
        trace.frames[size_t(k)].fovea_fragments_per_px = 10.0;
    RuntimeSimConfig cfg = ffrConfig(c, 10);
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    const LayerPlan plan = LayerPlanner(trace.header.profile).plan(trace.frames[2].gaze, 5.0);
    const double px = double(plan.eyes[0].fovea.pixels() + plan.eyes[1].fovea.pixels());
    EXPECT_NEAR(r.frames[2].t_local_ms, 10.0 * px * 1e-6, 1e-9);
    EXPECT_NEAR(r.frames[6].t_local_ms, 10.0 * px * 1e-6, 1e-9);
    EXPECT_NEAR(r.frames[5].t_local_ms, 2.5 * px * 1e-6, 1e-9);
    // The caller's counts, where given, win over the trace's.
    cfg.fovea_fragments = [](int64_t, const LayerPlan&, int) { return 1e6; };
    NoisyLink link2 = fastLink();
    EXPECT_NEAR(simulateRuntime(trace, cfg, link2).frames[2].t_local_ms, 2.0, 1e-9);
    // Local renders the whole frame: the same at frames 2 and 5.
    cfg.fovea_fragments = nullptr;
    cfg.design = Design::Local;
    NoisyLink link3 = fastLink();
    const RuntimeRunResult local = simulateRuntime(trace, cfg, link3);
    EXPECT_GT(local.frames[2].t_local_ms, 0.0);
    EXPECT_NEAR(local.frames[2].t_local_ms, local.frames[5].t_local_ms, 1e-9);
}

TEST(RuntimeModel, SwAndQvrPayTheRingCountsEveryFrame) {
    // The runtime counts the rings for qvr and sw (LIWC's model, fed reactively for sw), the
    // draw clusters at a constant cost: with only that and a 1 ms UCA, both are charged it in
    // every frame's headset time; ffr is not.
    RuntimeCosts c = flatCosts(0.0, 1.0, 1.0);
    c.decision = {4.0, 0.0, 0.0};
    for (Design d : {Design::Qvr, Design::Sw, Design::Ffr}) {
        const RuntimeRunResult r = run(d, c, 2, 30, 250.0, false);
        for (size_t k = 1; k < r.frames.size(); ++k)
            EXPECT_NEAR(r.frames[k].decision_ms, d == Design::Ffr ? 0.0 : 4.0, 1e-9)
                << static_cast<int>(d);
    }
}

// The model reads `qvr run --net` with the link grammar: rates and traces as the emulator runs
// them, delay_ms used, the other options accepted and not modelled, and a message for the rest.
TEST(RuntimeModel, LinksFromTheLinkGrammar) {
    double delay_ms = -1.0;
    auto lte = makeRuntimeLink("4g,delay_ms=7,loss=0.01", &delay_ms);
    ASSERT_TRUE(lte.ok()) << lte.error();
    EXPECT_EQ((*lte)->nominalBps(), 100e6);
    EXPECT_EQ((*lte)->meanGoodputBps(), 100e6);  // efficiency 1: headers are the model's
    EXPECT_EQ(delay_ms, 7.0);
    auto rate = makeRuntimeLink("rate:42", &delay_ms);
    ASSERT_TRUE(rate.ok()) << rate.error();
    EXPECT_EQ((*rate)->nominalBps(), 42e6);
    EXPECT_EQ(delay_ms, 0.0);
    const std::string trace =
        std::string(QVR_SOURCE_DIR) + "/../shared/data/network/TMobile-LTE-short.down";
    if (std::ifstream(trace).good()) {
        auto t = makeRuntimeLink("trace:" + trace + "@50", nullptr);
        ASSERT_TRUE(t.ok()) << t.error();
        EXPECT_EQ((*t)->nominalBps(), 50e6);
    }
    for (const std::string bad : {"none", "wlan", "", "lte,delay_ms=-1", "lte,foo=1", "rate:0",
                                  "trace:/nonexistent.down", "trace:"}) {
        auto r = makeRuntimeLink(bad, &delay_ms);
        ASSERT_FALSE(r.ok()) << "'" << bad << "' was accepted";
        EXPECT_FALSE(r.error().empty());
    }
}

// aimd runs in the model as the runtime runs it: EyeNexus's controller fed each frame's request
// and last arrival. On a fast link with a steady server the one-way delay holds, so e1 never
// rises; on a link far too slow for the periphery every frame misses the wait limit, each a
// loss, and e1 jumps up.
TEST(RuntimeModel, AimdFollowsTheLinksQueue) {
    const RuntimeRunResult fast = run(Design::Aimd, flatCosts(1.0, 1.0, 2.0), 2, 200);
    ASSERT_EQ(fast.frames.size(), 200u);
    EXPECT_LE(fast.frames[0].e1_deg, 5.3);
    for (size_t k = 1; k < fast.frames.size(); ++k) {
        EXPECT_TRUE(fast.frames[k].requested) << k;
        EXPECT_LE(fast.frames[k].e1_deg, fast.frames[k - 1].e1_deg + 1e-9) << k;
    }
    const WorkloadTrace trace = flatTrace(200);
    RuntimeSimConfig cfg;
    cfg.design = Design::Aimd;
    cfg.costs = flatCosts(1.0, 1.0, 2.0);
    cfg.pipeline_depth = 2;
    cfg.frames = 200;
    NoisyLink slow("slow", 2e4, 1.0, kInf, {0, 0}, 1);
    const RuntimeRunResult r = simulateRuntime(trace, cfg, slow);
    double top = 0.0;
    for (const RuntimeFrame& f : r.frames)
        top = std::max(top, f.e1_deg);
    EXPECT_GT(top, 10.0);
}

TEST(RuntimeModel, DesignNames) {
    EXPECT_EQ(parseDesign("qvr", DesignScope::Runtime)->design, Design::Qvr);
    EXPECT_EQ(parseDesign("local", DesignScope::Runtime)->design, Design::Local);
    EXPECT_FALSE(parseDesign("dfr", DesignScope::Runtime).ok());
    EXPECT_FALSE(parseDesign("", DesignScope::Runtime).ok());
}

TEST(RuntimeModel, FixedEIsAFixedFoveaAtItsE1) {
    // fixed:E runs as the runtime runs it: FFR's pipeline at e1 = E.
    auto spec = parseDesign("fixed:12", DesignScope::Runtime);
    ASSERT_TRUE(spec.ok()) << spec.error();
    RuntimeSimConfig cfg;
    cfg.design = spec->design;
    cfg.fixed_e1_deg = spec->fixed_e1_deg;
    cfg.costs = flatCosts(1.0, 1.0, 1.0);
    cfg.frames = 10;
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(flatTrace(10), cfg, link);
    ASSERT_EQ(r.frames.size(), 10u);
    for (const RuntimeFrame& f : r.frames)
        EXPECT_DOUBLE_EQ(f.e1_deg, 12.0);
}

TEST(RuntimeModel, ASlowServerIsNotASilentOne) {
    // remote, one frame in flight, 300 ms per whole-frame layer: streams 300 ms apart, each
    // frame needing 600 ms, later than the 250 ms limit. Until the second stream the server has
    // no spacing and is silent after a limit (frames shown a refresh apart); once two streams
    // are 300 ms apart it is given twice that, 600 ms, and every frame that asked waits the whole
    // limit from when the server could start on it and is reused — never one refresh. (The
    // frames the request window withheld wait for nothing.)
    const RuntimeRunResult r = run(Design::Remote, flatCosts(0.0, 1.0, 300.0), 1, 120);
    int waited = 0;
    for (const RuntimeFrame& f : r.frames) {
        if (f.local_end_ms < 700.0 || !f.requested)
            continue;
        EXPECT_TRUE(f.reused);
        EXPECT_GE(f.uca_start_ms - f.local_end_ms, 250.0 - 1e-6) << f.local_end_ms;
        ++waited;
    }
    EXPECT_GE(waited, 4);
}

TEST(RuntimeModel, TheStartUpLastsUntilTheServersFirstLayersAreOnScreen) {
    // remote at 300 ms per layer: its first frame's layers are all in at 600 ms, after one
    // wait limit and a stretch of frames re-warping nothing a refresh apart. With a warm-up of
    // 2 frames the statistics start at the first frame composed after those layers came (the
    // runtime's first shown_frame ≥ 0), not at frame 2.
    const WorkloadTrace trace = flatTrace(40);
    RuntimeSimConfig cfg;
    cfg.design = Design::Remote;
    cfg.costs = flatCosts(0.0, 1.0, 300.0);
    cfg.pipeline_depth = 1;
    cfg.frames = 40;
    cfg.warmup_frames = 2;
    NoisyLink link = fastLink();
    const RuntimeRunResult r = simulateRuntime(trace, cfg, link);
    double first_ms = 1e300;
    for (const RuntimeFrame& f : r.frames)
        if (f.remote_done_ms >= 0.0)
            first_ms = std::min(first_ms, f.remote_done_ms);
    ASSERT_GT(first_ms, 600.0);
    size_t skip = 0;
    while (r.frames[skip].uca_start_ms < first_ms)
        ++skip;
    ASSERT_GT(skip, 5u);  // frame 0 waits the limit, then frames a refresh apart
    EXPECT_EQ(r.summary.frames, 40 - static_cast<int>(skip));
    // The counted frames that asked each wait the whole limit, not a refresh (the server is slow,
    // not silent); those the request window withheld wait for nothing.
    int asked = 0;
    for (size_t k = skip; k < r.frames.size(); ++k) {
        const RuntimeFrame& f = r.frames[k];
        EXPECT_NEAR(f.uca_start_ms - f.local_end_ms, f.requested ? 250.0 : 0.0, 1e-6) << k;
        asked += f.requested ? 1 : 0;
    }
    EXPECT_GE(asked, 1);
    cfg.warmup_frames = 0;
    NoisyLink link0 = fastLink();
    EXPECT_EQ(simulateRuntime(trace, cfg, link0).summary.frames, 40);
}

}  // namespace
}  // namespace qvr
