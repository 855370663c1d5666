// The calibration's codec passes: the layers' streams over a run's span at every e1 (encode
// times, bits, key frames, padding), remote's whole frame through its own encoders, and the
// decode inside headset frames.
#include <array>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "calibration_bench.h"
#include "calibration_side_mix.h"
#include "qvr/workload/workload.h"

namespace qvr::experiment {

void copyCanvasPolicy(const CodecConfig& codec, RuntimeCosts& costs) {
    costs.canvas_align_px = codec.canvas_align_px;
    costs.canvas_headroom = codec.canvas_headroom;
    costs.canvas_shrink_ratio = codec.canvas_shrink_ratio;
    costs.canvas_shrink_after_frames = codec.canvas_shrink_after_frames;
    costs.keyint_frames = codec.keyint_frames;
}

namespace {

// The layers' pass skips its first frames, as a run's warm-up does; so does the whole frame's.
constexpr int kCodecWarmup = 10;

double canvasPx(const VideoEncoder& e) {
    return double(e.canvasWidth()) * double(e.canvasHeight());
}

// One layer stream of the codec pass at one e1: its running encoder, and beside it one fed
// the same frames after a first image 1.25× as wide and high, so it codes them into a larger
// canvas, as a run's stream does after e1 grew.
struct CodecStream {
    std::unique_ptr<VideoEncoder> enc;
    std::unique_ptr<VideoEncoder> padded;
    double idr_bytes = 0.0;       // the new encoder's key frame
    double periodic_bytes = 0.0;  // the key frame at keyint_frames
    std::vector<double> p_bytes;  // its P-frames after the warm-up
};

// The codec pass at one e1.
struct CodecPassAtE1 {
    std::array<CodecStream, 4> streams;          // eye × {middle, outer}
    std::array<std::vector<double>, 2> bits_px;  // P-frames' bits per pixel: middle, outer
    std::array<double, 2> scale{};
};

Status startPadded(CalibrationBench& b, CodecStream& st, ImageRgba8& big) {
    auto e = makeVideoEncoder(b.codec);
    if (!e)
        return makeError("codec: " + e.error());
    st.padded = std::move(*e);
    // The first image: the layer in the top-left of one 1.25× larger.
    big.resize(b.image.width() * 5 / 4, b.image.height() * 5 / 4);
    for (int y = 0; y < b.image.height(); ++y)
        std::copy_n(b.image.row(y), b.image.strideElems(), big.row(y));
    if (auto first = st.padded->encode(big); !first)
        return makeError("encode: " + first.error());
    return {};
}

// The padded stream's frame beside the snug one's: what its extra canvas cost.
Status codePadded(CalibrationBench& b, CodecStream& st, const EncodedFrame& snug, int step,
                  ImageRgba8& big, CalibrationSamples& s) {
    if (!st.padded)
        if (auto started = startPadded(b, st, big); !started)
            return started;
    auto penc = st.padded->encode(b.image);
    if (!penc)
        return makeError("encode: " + penc.error());
    const double extra = canvasPx(*st.padded) / std::max(1.0, canvasPx(*st.enc)) - 1.0;
    if (step >= kCodecWarmup && !snug.is_keyframe && !penc->is_keyframe && !snug.bytes.empty() &&
        extra > 0.05)
        s.padding.push_back({extra, double(penc->bytes.size()) / double(snug.bytes.size())});
    return {};
}

// Frame `step` of one eye's layer `li` at e1: rendered, encoded in its stream (and the padded
// one), its time, bits and key frames taken.
Status codeLayer(CalibrationBench& b, CodecPassAtE1& pass, const LayerPlan& plan, const Pose& head,
                 int eye, int li, int step, ImageRgba8& big, CalibrationSamples& s) {
    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
    const LayerRect& rect = li == 0 ? layers.middle : layers.outer;
    if (rect.empty())
        return {};
    const LayerKind kind = li == 0 ? LayerKind::kMiddle : LayerKind::kOuter;
    if (auto st = renderLayer(b.r(), b.profile, plan, head, static_cast<Eye>(eye), kind, b.image,
                              CameraOptions{}, b.holes);
        !st)
        return makeError("layer render: " + st.error());
    const size_t sid = static_cast<size_t>(eye * 2 + li);
    CodecStream& st = pass.streams[sid];
    if (!st.enc) {
        auto e = makeVideoEncoder(b.codec);
        if (!e)
            return makeError("codec: " + e.error());
        st.enc = std::move(*e);
    }
    auto enc = st.enc->encode(b.image);
    if (!enc)
        return makeError("encode: " + enc.error());
    // The encoder's time per pixel of the canvas it codes (the model charges the canvas), in a
    // running stream, where P-frames carry more bits than the first ones after a key frame.
    // Every third frame.
    if (step >= kCodecWarmup && step < b.codec_frames && step % 3 == 0 && !enc->is_keyframe &&
        !enc->bytes.empty())
        s.encode.push_back({enc->encode_ms, canvasPx(*st.enc), 0});
    if (step == 0 && enc->is_keyframe)
        st.idr_bytes = double(enc->bytes.size());
    if (step > 0 && step == b.codec.keyint_frames && enc->is_keyframe)
        st.periodic_bytes = double(enc->bytes.size());
    if (step >= b.codec_frames)
        return {};  // only the periodic key frame is taken from the extra frame
    if (step >= kCodecWarmup && !enc->is_keyframe && !enc->bytes.empty()) {
        const double bits = 8.0 * double(enc->bytes.size());
        pass.bits_px[size_t(li)].push_back(bits / double(rect.pixels()));
        pass.scale[size_t(li)] = rect.scale;
        s.bits[size_t(li)].push_back({rect.scale, double(rect.pixels()), bits, step});
        st.p_bytes.push_back(double(enc->bytes.size()));
    }
    return codePadded(b, st, *enc, step, big, s);
}

// Each stream's key frames over its mean P-frame (the scale the bits law has, fitBitsLaw), and
// what the e1 spent, for Calibration::codec_by_e1.
nlohmann::json closeCodecPass(double e1, const CodecPassAtE1& pass, CalibrationSamples& s) {
    std::array<double, 4> open_r{}, periodic_r{};
    for (size_t sid = 0; sid < 4; ++sid) {
        const CodecStream& st = pass.streams[sid];
        if (st.p_bytes.empty())
            continue;
        const double p_mean = meanOf(st.p_bytes);
        if (st.idr_bytes > 0.0) {
            open_r[sid] = st.idr_bytes / p_mean;
            s.keyframe_ratio[sid % 2].push_back(open_r[sid]);
        }
        if (st.periodic_bytes > 0.0) {
            periodic_r[sid] = st.periodic_bytes / p_mean;
            s.periodic_keyframe_ratio.push_back(periodic_r[sid]);
        }
    }
    return {{"e1_deg", e1},
            {"middle_scale", pass.scale[0]},
            {"middle_bits_per_px_median", upperMedian(pass.bits_px[0])},
            {"outer_scale", pass.scale[1]},
            {"outer_bits_per_px_median", upperMedian(pass.bits_px[1])},
            {"keyframe_ratio_per_stream", open_r},
            {"periodic_keyframe_ratio_per_stream", periodic_r}};
}

// remote's whole frame, one eye, at step `step` of its pass.
Status codeWholeFrame(CalibrationBench& b, std::unique_ptr<VideoEncoder>& enc,
                      const LayerPlan& full, const Pose& head, int eye, bool sampled,
                      CalibrationSamples& s) {
    if (auto st = renderLayer(b.r(), b.profile, full, head, static_cast<Eye>(eye),
                              LayerKind::kFovea, b.image);
        !st)
        return makeError("whole-frame render: " + st.error());
    if (!enc) {
        auto made = makeVideoEncoder(b.codec);
        if (!made)
            return makeError("codec: " + made.error());
        enc = std::move(*made);
    }
    auto out = enc->encode(b.image);
    if (!out)
        return makeError("whole-frame encode: " + out.error());
    if (sampled && !out->is_keyframe) {
        s.full_frame_bits_per_px.push_back(8.0 * double(out->bytes.size()) /
                                           (double(b.image.width()) * double(b.image.height())));
        // Its encode, against its canvas: the layers' law taken from their ~0.1 Mpx canvases
        // to a whole frame's 5 Mpx one over-charges it, so the whole frame gets its own scale,
        // as its render does.
        s.encode.push_back({out->encode_ms, canvasPx(*enc), 0, true});
    }
    return {};
}

}  // namespace

// The codec's bits, as a run at a steady e1 spends them: one encoder per stream carried over
// the consecutive frames of a default run's span (1/refresh apart), P-frames from the run's
// warm-up on; the short sequences of measureLayerSequences see only the first P-frames after a
// key frame, which under-predict a steady run's periphery. One frame past keyint_frames when
// the pass reaches it: the periodic key frame of a running stream costs less than a new
// encoder's first frame.
Expected<nlohmann::json> measureLayerCodec(CalibrationBench& b, CalibrationSamples& s) {
    const int frames = b.codec_frames;
    for (int k = 0; k < frames; ++k)
        s.frame_content_key.push_back(double(frameContentKey(
            poseAt(b.inputs.traces.motion, contentTimeMs(k, b.profile.refresh_hz)))));
    const int pass_frames = b.codec.keyint_frames == frames ? frames + 1 : frames;
    nlohmann::json codec_by_e1 = nlohmann::json::array();
    ImageRgba8 big;
    for (double e1 : b.e1s) {
        CodecPassAtE1 pass;
        for (int step = 0; step < pass_frames; ++step) {
            // As `qvr run` times its frame `step`: the frame-by-frame bits apply where the head
            // poses agree.
            const double t_ms = contentTimeMs(step, b.profile.refresh_hz);
            const Pose head = poseAt(b.inputs.traces.motion, t_ms);
            const LayerPlan plan = b.planner->plan(gazeAt(b.inputs.traces.gaze, t_ms), e1);
            for (int eye = 0; eye < 2; ++eye)
                for (int li = 0; li < 2; ++li)
                    if (auto st = codeLayer(b, pass, plan, head, eye, li, step, big, s); !st)
                        return makeError(st.error());
        }
        codec_by_e1.push_back(closeCodecPass(e1, pass, s));
        b.log(fmt::format("  codec: {} frames at e1 = {} deg\n", frames, e1));
    }
    return codec_by_e1;
}

// remote's whole frame (one layer per eye at scale 1) in its own codec pass: the layers' law,
// fitted at scales ~2.5–12 and taken to scale 1, over-predicts remote's bits 2×. Consecutive
// frames of the run's span from its warm-up on, fresh encoders (the first is their key frame).
// P-frames from the encoder's seventh frame on: the first P-frames after a key frame are cheap
// while x264's rate control settles.
Status measureWholeFrameCodec(CalibrationBench& b, CalibrationSamples& s) {
    const int steps = b.options.quick ? 12 : 18;
    constexpr int kRamp = 6;
    std::array<std::unique_ptr<VideoEncoder>, 2> enc;
    const size_t before = s.full_frame_bits_per_px.size();
    for (int step = 0; step < steps; ++step) {
        const double t_ms = b.frameMs() * (kCodecWarmup + step);
        const Pose head = poseAt(b.inputs.traces.motion, t_ms);
        const LayerPlan full = b.planner->plan(gazeAt(b.inputs.traces.gaze, t_ms), 180.0);
        for (int eye = 0; eye < 2; ++eye)
            if (auto st = codeWholeFrame(b, enc[static_cast<size_t>(eye)], full, head, eye,
                                         step >= kRamp, s);
                !st)
                return st;
    }
    b.log(fmt::format("  whole frame codec: {} P-frames\n",
                      s.full_frame_bits_per_px.size() - before));
    return {};
}

// The decode where the headset decodes: in a headset frame (SideMix), after the previous frame's
// UCA and this frame's fovea, whose memory traffic has evicted the decoder's pictures from the
// caches; timed right after its own encode, a layer's decode reads 2.4× too fast. Per canvas
// pixel, P-frames only.
Status measureDecodes(CalibrationBench& b, CalibrationSamples& s) {
    const std::vector<double> decode_e1s =
        b.options.quick ? std::vector<double>{4, 10, 20} : std::vector<double>{3, 5, 8, 12, 18, 28};
    const int frames = b.options.quick ? 8 : 12;  // under SideMix::kStreamFrames: no key frame
    for (double e1 : decode_e1s) {
        SideMix mix(b.r(), b.profile, b.inputs, b.codec, e1);
        if (auto st = mix.headset(0); !st)  // codes the streams; decodes their key frames
            return makeError("decode pass: " + st.error());
        mix.recordDecodes(&s.decode);
        for (int k = 1; k <= frames; ++k)
            if (auto st = mix.headset(k); !st)
                return makeError("decode pass: " + st.error());
    }
    b.log(fmt::format("  decode in headset frames: {} decodes at e1 {}\n", s.decode.size(),
                      fmt::join(decode_e1s, ", ")));
    return {};
}

}  // namespace qvr::experiment
