// H.264 layer streams through libavcodec + libx264 with low-latency settings (paper §3.2: the
// server streams each periphery layer as video; the headset decodes it before UCA composes).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include <fmt/format.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include "backends.h"
#include "ffmpeg_util.h"
#include "qvr/codec/frame_header.h"
#include "qvr/core/canvas_policy.h"
#include "qvr/core/clock.h"

namespace qvr::detail {

namespace {

struct ContextDeleter {
    void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameDeleter {
    void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketDeleter {
    void operator()(AVPacket* p) const { av_packet_free(&p); }
};
using ContextPtr = std::unique_ptr<AVCodecContext, ContextDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;

// swscale's SIMD paths process pixels in groups and may touch a few pixels past a row's end, so
// rows handed to it are 64-byte aligned with slack; a tightly packed image of another width is
// staged through this buffer.
constexpr int kRowAlignBytes = 64;
int alignedStride(int width) {
    return (width * 4 + 2 * kRowAlignBytes - 1) / kRowAlignBytes * kRowAlignBytes;
}
bool directOk(int width) {
    return (width * 4) % kRowAlignBytes == 0;
}

// Fills the canvas outside the layer. Up to the end of the coding block the layer's edge falls
// in (and at least kEdgeMarginPx past the edge) the layer's last column and row repeat, so the
// deblocking filter, which reaches 3 pixels across a block edge, finds no foreign colour to bleed
// into the layer. Beyond that the padding is one constant, the same in every frame, which a
// P-frame codes as skipped blocks; edge pixels repeated over the whole margin would change with
// the content every frame and be paid for in every P-frame.
constexpr int kEdgeMarginPx = 4;
constexpr double kQcomp = 0.6;  // x264's quantiser-curve compression (its default)
int edgeEnd(int size, int canvas, int block) {
    const int end = (size + kEdgeMarginPx + block - 1) / block * block;
    return std::min(end, canvas);
}
void padPlane(uint8_t* plane, int stride, int w, int h, int canvas_w, int canvas_h, int block,
              uint8_t fill) {
    const int edge_w = edgeEnd(w, canvas_w, block);
    const int edge_h = edgeEnd(h, canvas_h, block);
    for (int y = 0; y < h; ++y) {
        uint8_t* row = plane + static_cast<ptrdiff_t>(y) * stride;
        std::memset(row + w, row[w - 1], static_cast<size_t>(edge_w - w));
        std::memset(row + edge_w, fill, static_cast<size_t>(canvas_w - edge_w));
    }
    const uint8_t* last = plane + static_cast<ptrdiff_t>(h - 1) * stride;
    for (int y = h; y < edge_h; ++y)
        std::memcpy(plane + static_cast<ptrdiff_t>(y) * stride, last,
                    static_cast<size_t>(canvas_w));
    for (int y = edge_h; y < canvas_h; ++y)
        std::memset(plane + static_cast<ptrdiff_t>(y) * stride, fill,
                    static_cast<size_t>(canvas_w));
}

// What the encoder and the decoder both hold: the codec context, one frame and one packet, the
// RGBA/YUV converter (freed with them) and the staging buffer for rows swscale cannot take as
// they are.
class FfmpegState {
public:
    FfmpegState(const FfmpegState&) = delete;
    FfmpegState& operator=(const FfmpegState&) = delete;

protected:
    FfmpegState() = default;
    ~FfmpegState() { sws_freeContext(m_sws); }

    ContextPtr m_ctx;
    FramePtr m_frame;
    PacketPtr m_packet;
    SwsContext* m_sws = nullptr;
    std::vector<uint8_t> m_staging;
};

class X264Encoder final : public VideoEncoder, private FfmpegState {
public:
    explicit X264Encoder(const CodecConfig& config)
        : m_config(config),
          m_canvas(config.canvas_align_px, config.canvas_headroom, config.canvas_shrink_ratio,
                   config.canvas_shrink_after_frames, config.max_side_px) {}

    Expected<EncodedFrame> encode(const ImageRgba8& image, bool force_keyframe) override {
        const Stopwatch t0;
        const int w = image.width();
        const int h = image.height();
        if (w < 1 || h < 1 || w > m_config.max_side_px || h > m_config.max_side_px)
            return makeError(fmt::format("x264 encoder: layer size {}x{} outside [1, {}]", w, h,
                                         m_config.max_side_px));
        // An IDR comes anyway when asked for or at keyint (x264 counts from the last IDR).
        const bool periodic = m_config.keyint_frames > 0 && !m_config.intra_refresh &&
                              m_since_idr + 1 >= m_config.keyint_frames;
        const CanvasSize canvas = m_canvas.next(w, h, force_keyframe || m_force_key || periodic);
        const bool new_canvas = m_canvas.changed() || !m_ctx;
        if (new_canvas) {
            if (m_ctx)
                ++m_stats.reopens;
            if (Status s = open(canvas); !s) {
                m_ctx.reset();
                m_canvas = CanvasPolicy(m_config.canvas_align_px, m_config.canvas_headroom,
                                        m_config.canvas_shrink_ratio,
                                        m_config.canvas_shrink_after_frames, m_config.max_side_px);
                return makeError(s.error());
            }
            m_force_key = true;  // a new SPS: the decoder must restart from an IDR
        }
        if (Status s = convert(image); !s)
            return makeError(s.error());
        if (Status s = followPadding(w, h); !s)
            return makeError(s.error());

        const bool key = force_keyframe || m_force_key;
        m_frame->pict_type = key ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
        m_frame->pts = m_pts++;
        int err = avcodec_send_frame(m_ctx.get(), m_frame.get());
        if (err < 0)
            return makeError("x264 encoder: send_frame: " + avErrorText(err));
        m_payload.clear();
        for (;;) {
            err = avcodec_receive_packet(m_ctx.get(), m_packet.get());
            if (err == kAvErrorEagain || err == kAvErrorEof)
                break;
            if (err < 0)
                return makeError("x264 encoder: receive_packet: " + avErrorText(err));
            m_payload.insert(m_payload.end(), m_packet->data, m_packet->data + m_packet->size);
            av_packet_unref(m_packet.get());
        }
        if (m_payload.empty())
            return makeError("x264 encoder: no packet for the frame (encoder delay is not zero)");

        // Whether the decoder can start here is a property of the bytes: look for an IDR slice
        // rather than trusting the request (x264 may also decide on its own, e.g. at keyint).
        const bool idr = annexBHasIdr(m_payload);
        if (idr)
            m_force_key = false;
        m_since_idr = idr ? 0 : m_since_idr + 1;
        FrameHeader fh;
        fh.flags = static_cast<uint8_t>((idr ? FrameHeader::kFlagKeyframe : 0) |
                                        (new_canvas ? FrameHeader::kFlagNewCanvas : 0));
        fh.refresh_frames =
            m_config.intra_refresh ? static_cast<uint16_t>(m_config.keyint_frames) : 0;
        fh.frame_id = m_next_id++;
        fh.width = static_cast<uint16_t>(w);
        fh.height = static_cast<uint16_t>(h);
        EncodedFrame out = packEncodedFrame(fh, m_payload, m_stats);
        out.encode_ms = t0.elapsedMs();
        return out;
    }

    void requestKeyframe() override { m_force_key = true; }

    // x264's CRF takes a frame's quantiser from its mean complexity per macroblock
    // (qscale ∝ (complexity / macroblocks)^(1 − qcomp)), and the canvas's constant padding has
    // none: left alone, a layer far smaller than its canvas is coded finer, at several times the
    // bytes, than the same layer in a snug one. Raising crf by 6·(1 − qcomp)·log2(canvas
    // macroblocks / layer macroblocks) undoes that dilution (libavcodec hands a changed crf to
    // x264_encoder_reconfig before the next frame).
    Status followPadding(int w, int h) {
        if (m_config.bitrate_bps > 0)
            return Status::success();
        const auto mbs = [](int a, int b) { return std::ceil(a / 16.0) * std::ceil(b / 16.0); };
        const double dilution = mbs(m_ctx->width, m_ctx->height) / mbs(w, h);
        const double crf =
            std::min(51.0, m_config.crf + 6.0 * (1.0 - kQcomp) * std::log2(dilution));
        if (std::abs(crf - m_crf) < 0.05)
            return Status::success();
        if (av_opt_set_double(m_ctx->priv_data, "crf", crf, 0) < 0)
            return makeError("x264 encoder: libx264 rejected crf");
        m_crf = crf;
        return Status::success();
    }
    const EncoderStats& stats() const override { return m_stats; }
    int canvasWidth() const override { return m_ctx ? m_ctx->width : 0; }
    int canvasHeight() const override { return m_ctx ? m_ctx->height : 0; }

private:
    Status open(CanvasSize canvas) {
        const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
        if (!codec)
            return makeError("x264 encoder: libavcodec was built without libx264");
        ContextPtr ctx(avcodec_alloc_context3(codec));
        if (!ctx)
            return makeError("x264 encoder: out of memory");
        ctx->width = canvas.width;
        ctx->height = canvas.height;
        ctx->pix_fmt = AV_PIX_FMT_YUV420P;
        const int rate_milli = static_cast<int>(std::lround(m_config.frame_rate_hz * 1000.0));
        ctx->time_base = AVRational{1000, rate_milli};
        ctx->framerate = AVRational{rate_milli, 1000};
        ctx->max_b_frames = 0;  // B-frames add a frame of delay; the headset cannot wait
        ctx->thread_count = m_config.threads;
        ctx->slices = m_config.slices;
        ctx->gop_size = m_config.keyint_frames > 0 ? m_config.keyint_frames : 0;
        if (m_config.bitrate_bps > 0) {
            // One frame of VBV buffer: a frame may not burst past what the link carries in a
            // frame time, the constraint a per-frame deadline imposes.
            ctx->bit_rate = m_config.bitrate_bps;
            ctx->rc_max_rate = m_config.bitrate_bps;
            ctx->rc_buffer_size = static_cast<int>(
                std::min<double>(2e9, m_config.bitrate_bps / m_config.frame_rate_hz));
        }
        void* priv = ctx->priv_data;
        // qcomp pinned at x264's default: followPadding() depends on it.
        std::string params = fmt::format("repeat-headers=1:scenecut=0:qcomp={}", kQcomp);
        if (m_config.keyint_frames == 0)
            params += ":keyint=infinite";
        if (av_opt_set(priv, "preset", m_config.preset.c_str(), 0) < 0 ||
            av_opt_set(priv, "tune", "zerolatency", 0) < 0 ||
            av_opt_set(priv, "forced-idr", "1", 0) < 0 ||
            av_opt_set(priv, "x264-params", params.c_str(), 0) < 0)
            return makeError("x264 encoder: libx264 rejected an option");
        if (m_config.bitrate_bps == 0 &&
            av_opt_set(priv, "crf", std::to_string(m_config.crf).c_str(), 0) < 0)
            return makeError("x264 encoder: libx264 rejected crf");
        m_crf = m_config.crf;
        if (m_config.intra_refresh && av_opt_set(priv, "intra-refresh", "1", 0) < 0)
            return makeError("x264 encoder: libx264 rejected intra-refresh");
        int err = avcodec_open2(ctx.get(), codec, nullptr);
        if (err < 0)
            return makeError(fmt::format("x264 encoder: open {}x{}: {}", canvas.width,
                                         canvas.height, avErrorText(err)));
        FramePtr frame(av_frame_alloc());
        PacketPtr packet(av_packet_alloc());
        if (!frame || !packet)
            return makeError("x264 encoder: out of memory");
        frame->format = AV_PIX_FMT_YUV420P;
        frame->width = canvas.width;
        frame->height = canvas.height;
        err = av_frame_get_buffer(frame.get(), kRowAlignBytes);
        if (err < 0)
            return makeError("x264 encoder: frame buffer: " + avErrorText(err));
        m_ctx = std::move(ctx);
        m_frame = std::move(frame);
        m_packet = std::move(packet);
        return Status::success();
    }

    Status convert(const ImageRgba8& image) {
        const int w = image.width();
        const int h = image.height();
        if (int err = av_frame_make_writable(m_frame.get()); err < 0)
            return makeError("x264 encoder: frame not writable: " + avErrorText(err));
        m_sws = sws_getCachedContext(m_sws, w, h, AV_PIX_FMT_RGBA, w, h, AV_PIX_FMT_YUV420P,
                                     SWS_BILINEAR, nullptr, nullptr, nullptr);
        if (!m_sws)
            return makeError(
                fmt::format("x264 encoder: no RGBA→YUV420 conversion for {}x{}", w, h));
        const uint8_t* src = image.data();
        int src_stride = w * 4;
        if (!directOk(w)) {
            src_stride = alignedStride(w);
            m_staging.resize(static_cast<size_t>(src_stride) * (h + 1));
            for (int y = 0; y < h; ++y)
                std::memcpy(m_staging.data() + static_cast<size_t>(y) * src_stride, image.row(y),
                            static_cast<size_t>(w) * 4);
            src = m_staging.data();
        }
        const uint8_t* src_planes[4] = {src, nullptr, nullptr, nullptr};
        const int src_strides[4] = {src_stride, 0, 0, 0};
        sws_scale(m_sws, src_planes, src_strides, 0, h, m_frame->data, m_frame->linesize);
        const int cw = m_frame->width;
        const int ch = m_frame->height;
        // H.264 codes 16×16 luma blocks, 8×8 in each 4:2:0 chroma plane; the constant is black.
        padPlane(m_frame->data[0], m_frame->linesize[0], w, h, cw, ch, 16, 16);
        for (int p = 1; p < 3; ++p)
            padPlane(m_frame->data[p], m_frame->linesize[p], (w + 1) / 2, (h + 1) / 2, cw / 2,
                     ch / 2, 8, 128);
        return Status::success();
    }

    CodecConfig m_config;
    CanvasPolicy m_canvas;
    int m_since_idr = 0;  // frames coded since the newest IDR
    std::vector<uint8_t> m_payload;
    EncoderStats m_stats;
    int64_t m_pts = 0;
    uint32_t m_next_id = 0;
    bool m_force_key = true;
    double m_crf = 0.0;  // the crf libx264 holds now
};

class H264Decoder final : public FramedDecoder, private FfmpegState {
public:
    H264Decoder() : FramedDecoder(false, "h264 decoder") {}

    Status open() {
        const AVCodec* codec = avcodec_find_decoder(AV_CODEC_ID_H264);
        if (!codec)
            return makeError("h264 decoder: libavcodec has no H.264 decoder");
        ContextPtr ctx(avcodec_alloc_context3(codec));
        if (!ctx)
            return makeError("h264 decoder: out of memory");
        // One thread and low delay: a packet in, its picture out, no frame-threading queue.
        ctx->thread_count = 1;
        ctx->flags |= AV_CODEC_FLAG_LOW_DELAY;
        int err = avcodec_open2(ctx.get(), codec, nullptr);
        if (err < 0)
            return makeError("h264 decoder: open: " + avErrorText(err));
        m_frame.reset(av_frame_alloc());
        m_packet.reset(av_packet_alloc());
        if (!m_frame || !m_packet)
            return makeError("h264 decoder: out of memory");
        m_ctx = std::move(ctx);
        return Status::success();
    }

private:
    Expected<ImageRgba8> decodePayload(const FrameHeader& h,
                                       std::span<const uint8_t> payload) override {
        if (h.keyframe() && !annexBHasIdr(payload))
            return makeError(
                fmt::format("h264 decoder: frame {} claims to be a key frame but "
                            "holds no IDR slice",
                            h.frame_id));
        auto picture = feedPayload(h, payload);
        tracker().decoded(h, picture.ok());
        if (!picture)
            return makeError(picture.error());
        if (tracker().withholdPicture())
            return makeError(
                fmt::format("h264 decoder: frame {} decoded while recovering from "
                            "loss; {} more frame(s) until the intra refresh completes",
                            h.frame_id, tracker().recoveringFrames()));
        return toRgba(h);
    }

    // Feeds one payload and takes its picture; leaves it in m_frame.
    Status feedPayload(const FrameHeader& h, std::span<const uint8_t> payload) {
        // libavcodec reads up to AV_INPUT_BUFFER_PADDING_SIZE bytes past a packet's end.
        m_buffer.assign(payload.size() + AV_INPUT_BUFFER_PADDING_SIZE, 0);
        std::memcpy(m_buffer.data(), payload.data(), payload.size());
        av_packet_unref(m_packet.get());
        m_packet->data = m_buffer.data();
        m_packet->size = static_cast<int>(payload.size());
        int err = avcodec_send_packet(m_ctx.get(), m_packet.get());
        m_packet->data = nullptr;
        m_packet->size = 0;
        if (err < 0)
            return makeError(
                fmt::format("h264 decoder: frame {}: {}", h.frame_id, avErrorText(err)));
        av_frame_unref(m_frame.get());
        err = avcodec_receive_frame(m_ctx.get(), m_frame.get());
        if (err == kAvErrorEagain)
            return makeError(
                fmt::format("h264 decoder: frame {}: the bytes held no picture", h.frame_id));
        if (err < 0)
            return makeError(
                fmt::format("h264 decoder: frame {}: {}", h.frame_id, avErrorText(err)));
        if ((m_frame->flags & AV_FRAME_FLAG_CORRUPT) != 0 || m_frame->decode_error_flags != 0)
            return makeError(
                fmt::format("h264 decoder: frame {}: picture damaged (concealed "
                            "errors)",
                            h.frame_id));
        if (m_frame->format != AV_PIX_FMT_YUV420P && m_frame->format != AV_PIX_FMT_YUVJ420P)
            return makeError(fmt::format("h264 decoder: frame {}: unexpected pixel format {}",
                                         h.frame_id, m_frame->format));
        if (m_frame->width < h.width || m_frame->height < h.height)
            return makeError(
                fmt::format("h264 decoder: frame {}: picture {}x{} smaller than "
                            "the layer {}x{}",
                            h.frame_id, m_frame->width, m_frame->height, h.width, h.height));
        return Status::success();
    }

    Expected<ImageRgba8> toRgba(const FrameHeader& h) {
        const int w = h.width;
        const int ht = h.height;
        // swscale converts YUV 4:2:0 to RGBA with its unscaled kernel only for an even height;
        // any other size goes through its general scaler at 1:1, ~4x slower (a run's headset:
        // 0.43 ms a layer against 0.10 ms, docs/CODEC.md "Decoding to RGBA"). The canvas is
        // padded past the layer to the codec's blocks, so the conversion covers a size the kernel
        // takes (even height, width a multiple of 16) where the canvas has it, and the copy
        // crops to the layer.
        const int cw = std::min((w + 15) / 16 * 16, m_frame->width);
        const int ch = std::min((ht + 1) / 2 * 2, m_frame->height);
        const auto format = static_cast<AVPixelFormat>(m_frame->format);
        m_sws = sws_getCachedContext(m_sws, cw, ch, format, cw, ch, AV_PIX_FMT_RGBA, SWS_BILINEAR,
                                     nullptr, nullptr, nullptr);
        if (!m_sws)
            return makeError(
                fmt::format("h264 decoder: no YUV420→RGBA conversion for {}x{}", cw, ch));
        ImageRgba8 image(w, ht);
        // The layer sits at the canvas's top-left, so the planes need no offset: crop by size.
        if (cw == w && ch == ht && directOk(w)) {
            uint8_t* dst[4] = {image.data(), nullptr, nullptr, nullptr};
            const int dst_strides[4] = {w * 4, 0, 0, 0};
            sws_scale(m_sws, m_frame->data, m_frame->linesize, 0, ht, dst, dst_strides);
        } else {
            const int stride = alignedStride(cw);
            m_staging.resize(static_cast<size_t>(stride) * (ch + 1));
            uint8_t* dst[4] = {m_staging.data(), nullptr, nullptr, nullptr};
            const int dst_strides[4] = {stride, 0, 0, 0};
            sws_scale(m_sws, m_frame->data, m_frame->linesize, 0, ch, dst, dst_strides);
            for (int y = 0; y < ht; ++y)
                std::memcpy(image.row(y), m_staging.data() + static_cast<size_t>(y) * stride,
                            static_cast<size_t>(w) * 4);
        }
        return image;
    }

    std::vector<uint8_t> m_buffer;
};

}  // namespace

Expected<std::unique_ptr<VideoEncoder>> makeX264Encoder(const CodecConfig& config) {
    quietFfmpegLog();
    if (!avcodec_find_encoder_by_name("libx264"))
        return makeError("x264 encoder: libavcodec was built without libx264");
    return std::unique_ptr<VideoEncoder>(std::make_unique<X264Encoder>(config));
}

Expected<std::unique_ptr<VideoDecoder>> makeH264Decoder() {
    quietFfmpegLog();
    auto decoder = std::make_unique<H264Decoder>();
    if (Status s = decoder->open(); !s)
        return makeError(s.error());
    return std::unique_ptr<VideoDecoder>(std::move(decoder));
}

}  // namespace qvr::detail
