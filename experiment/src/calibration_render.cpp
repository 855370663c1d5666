// The calibration's render passes: the layers of short frame sequences at every pose and e1
// (fovea, periphery, UCA) and the full frame at every pose (local's pass, remote's layer, UCA
// over it, the display video's copy).
#include <array>
#include <memory>

#include <fmt/format.h>

#include "calibration_bench.h"
#include "qvr/experiment/scanout_recorder.h"

namespace qvr::experiment {

namespace {

// A stream's encoder and decoder, which see successive frames (P-frames).
struct Chain {
    std::unique_ptr<VideoEncoder> enc;
    std::unique_ptr<VideoDecoder> dec;
};
using Chains = std::array<Chain, 4>;  // stream ids: eye × {middle, outer}

// Consecutive frames (1/refresh apart, as a run's content advances) so the codec sees the
// motion of a run. Each sequence starts fresh encoders: frame 0 is their key frame, frame 1 the
// first P-frame, which refers to that key frame and costs ~25% fewer bits than the P-frames
// after it. The times are sampled from frame 2 on (UCA's) or at frame 0 (the fovea's); the
// bits come from the longer codec pass (calibration_codec.cpp).
constexpr int kSequenceFrames = 6;
constexpr int kFirstSampled = 2;

// One eye's periphery layer `li` (0 middle, 1 outer) rendered, timed, encoded and decoded.
Status sequenceLayer(CalibrationBench& b, const LayerPlan& plan, const Pose& head, int eye, int li,
                     EyeLayerImages& imgs, Chains& chains, CalibrationSamples& s) {
    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
    const bool middle = li == 0;
    const LayerRect& rect = middle ? layers.middle : layers.outer;
    if (rect.empty())
        return {};
    ImageRgba8& img = middle ? imgs.middle : imgs.outer;
    const LayerKind kind = middle ? LayerKind::kMiddle : LayerKind::kOuter;
    const auto t0 = CalibrationClock::now();
    auto st = renderLayer(b.r(), b.profile, plan, head, static_cast<Eye>(eye), kind, img,
                          CameraOptions{}, b.holes);
    if (!st)
        return makeError("layer render: " + st.error());
    const double ms = msSince(t0);
    s.server_render.push_back({ms, double(rect.pixels()), b.drawnTriangles(plan, head, eye, kind),
                               false, fragmentsOf(*st)});
    Chain& ch = chains[static_cast<size_t>(eye * 2 + li)];
    if (!ch.enc) {
        auto e = makeVideoEncoder(b.codec);
        auto d = makeVideoDecoder(b.codec);
        if (!e || !d)
            return makeError("codec: " + (e ? d.error() : e.error()));
        ch.enc = std::move(*e);
        ch.dec = std::move(*d);
    }
    auto enc = ch.enc->encode(img);
    if (!enc)
        return makeError("encode: " + enc.error());
    // Decoded as a run's headset would, untimed: the decode's cost is measureDecodes', where the
    // headset decodes.
    if (auto dec = ch.dec->decode(enc->bytes); !dec)
        return makeError("decode: " + dec.error());
    return {};
}

// Frame `step` of the sequence at pose `pi` and e1: both eyes' layers, then UCA over them.
Status sequenceFrame(CalibrationBench& b, size_t pi, double e1, int step, Chains& chains,
                     CalibrationSamples& s) {
    const double t_ms = poseTimeMs(static_cast<int>(pi)) + b.frameMs() * step;
    const Pose head = poseAt(b.inputs.traces.motion, t_ms);
    const LayerPlan plan = b.planner->plan(gazeAt(b.inputs.traces.gaze, t_ms), e1);
    auto frame = std::make_shared<LayerFrame>();
    frame->plan = plan;
    frame->render_pose = head;
    double layer_px = 0.0;
    for (int eye = 0; eye < 2; ++eye) {
        const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
        EyeLayerImages& imgs = frame->eyes[static_cast<size_t>(eye)];
        layer_px += double(layers.fovea.pixels() + layers.middle.pixels() + layers.outer.pixels());
        if (!layers.fovea.empty()) {
            const auto t0 = CalibrationClock::now();
            auto st = renderLayer(b.r(), b.profile, plan, head, static_cast<Eye>(eye),
                                  LayerKind::kFovea, imgs.fovea);
            if (!st)
                return makeError("fovea render: " + st.error());
            const double ms = msSince(t0);
            if (step == 0)
                s.fovea.push_back({ms, double(layers.fovea.pixels()),
                                   b.drawnTriangles(plan, head, eye, LayerKind::kFovea), false,
                                   fragmentsOf(*st)});
        }
        for (int li = 0; li < 2; ++li)
            if (auto st = sequenceLayer(b, plan, head, eye, li, imgs, chains, s); !st)
                return st;
    }
    const auto t0 = CalibrationClock::now();
    auto rep = b.compositor->present(frame, head, b.display);
    const double uca_ms = msSince(t0);
    if (!rep)
        return makeError("UCA: " + rep.error());
    if (step >= kFirstSampled)
        s.uca.push_back({uca_ms, layer_px, 0});
    return {};
}

// The full frame at pose p: both eyes rendered whole, then UCA over it twice, each followed by
// the display video's copy.
Status fullFrame(CalibrationBench& b, const CalibrationPose& p, ScanoutRecorder& video_stand_in,
                 CalibrationSamples& s) {
    const LayerPlan full = b.planner->plan(p.gaze, 180.0);
    auto frame = std::make_shared<LayerFrame>();
    frame->plan = full;
    frame->render_pose = p.head;
    for (int eye = 0; eye < 2; ++eye) {
        ImageRgba8& img = frame->eyes[static_cast<size_t>(eye)].fovea;
        const auto t0 = CalibrationClock::now();
        auto st = renderLayer(b.r(), b.profile, full, p.head, static_cast<Eye>(eye),
                              LayerKind::kFovea, img);
        if (!st)
            return makeError("full render: " + st.error());
        const double ms = msSince(t0);
        const double tris = b.drawnTriangles(full, p.head, eye, LayerKind::kFovea);
        s.fovea.push_back({ms, b.eye_px, tris, true, fragmentsOf(*st)});
        // The server's whole-frame layer is the same view at scale 1.
        s.server_render.push_back({ms, b.eye_px, tris, true, fragmentsOf(*st)});
    }
    for (int rep_i = 0; rep_i < 2; ++rep_i) {
        const auto t0 = CalibrationClock::now();
        auto rep = b.compositor->present(frame, p.head, b.display);
        if (!rep)
            return makeError("UCA: " + rep.error());
        s.uca.push_back({msSince(t0), 2.0 * b.eye_px, 0});
        // The display video's copy (`qvr run --video`): every design's headset copies its
        // scan-out at a quarter resolution right after UCA wrote it (ScanoutRecorder; its
        // stand-in for the designs not kept). The display must be the one UCA just wrote, as
        // in a run: timed back to back over one display, the copy read under a third of what
        // a run's headset paid.
        const auto t1 = CalibrationClock::now();
        video_stand_in.onScanout(runtime::FrameTelemetry{}, full, b.display);
        s.video_copy_ms.push_back(msSince(t1));
    }
    return {};
}

}  // namespace

Status measureLayerSequences(CalibrationBench& b, CalibrationSamples& s) {
    for (size_t pi = 0; pi < b.poses.size(); ++pi) {
        for (double e1 : b.e1s) {
            // Each sequence codes into fresh encoders, as a run's streams at a steady e1 do: one
            // chain carried across e1 would keep a canvas sized for the largest layer it had
            // seen (docs/CODEC.md "Canvas policy") and charge its padding to the smaller layers.
            Chains chains;
            for (int step = 0; step < kSequenceFrames; ++step)
                if (auto st = sequenceFrame(b, pi, e1, step, chains, s); !st)
                    return st;
        }
        b.log(fmt::format("  pose {}/{}: fovea, periphery layers, codec, UCA\n", pi + 1,
                          b.poses.size()));
    }
    return {};
}

Status measureFullFrames(CalibrationBench& b, CalibrationSamples& s) {
    // At every pose (~0.1-0.2 s a view): the whole frame's scale is their median, which a few
    // samples leave at the mercy of one slow moment of the host.
    ScanoutRecorder video_stand_in(b.profile, 1, false, /*keep=*/false);
    video_stand_in.reserve(1);
    for (size_t pi = 0; pi < b.poses.size(); ++pi) {
        if (auto st = fullFrame(b, b.poses[pi], video_stand_in, s); !st)
            return st;
        b.log(fmt::format("  full frame {}/{}\n", pi + 1, b.poses.size()));
    }
    b.log(fmt::format("  display video copy after UCA: {:.2f} ms a frame (median of {})\n",
                      upperMedian(s.video_copy_ms), s.video_copy_ms.size()));
    return {};
}

}  // namespace qvr::experiment
