// MP4 display video through libavcodec (libx264) and libavformat (mp4_writer.h).
#include "qvr/codec/mp4_writer.h"

#include "ffmpeg_util.h"

#include <mutex>

#include <fmt/format.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace qvr {

namespace {

class AvMp4Writer final : public Mp4Writer {
public:
    AvMp4Writer(std::string path, int width, int height)
        : m_path(std::move(path)), m_w(width), m_h(height) {}
    ~AvMp4Writer() override {
        if (m_fmt && !(m_fmt->oformat->flags & AVFMT_NOFILE) && m_fmt->pb)
            avio_closep(&m_fmt->pb);
        avformat_free_context(m_fmt);
        avcodec_free_context(&m_enc);
        av_frame_free(&m_frame);
        av_packet_free(&m_pkt);
        sws_freeContext(m_sws);
    }

    Status init(int fps, int crf) {
        int err = avformat_alloc_output_context2(&m_fmt, nullptr, "mp4", m_path.c_str());
        if (err < 0 || !m_fmt)
            return makeError("mp4: no MP4 muxer in libavformat: " + detail::avErrorText(err));
        const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
        if (!codec)
            return makeError("mp4: libavcodec was built without libx264");
        m_enc = avcodec_alloc_context3(codec);
        m_frame = av_frame_alloc();
        m_pkt = av_packet_alloc();
        if (!m_enc || !m_frame || !m_pkt)
            return makeError("mp4: out of memory");
        m_enc->width = m_w;
        m_enc->height = m_h;
        m_enc->pix_fmt = AV_PIX_FMT_YUV420P;  // what browsers decode
        m_enc->time_base = AVRational{1, fps};
        m_enc->framerate = AVRational{fps, 1};
        m_enc->gop_size = fps;  // a key frame a second: seeking in the player
        m_enc->max_b_frames = 0;
        m_enc->thread_count = 1;
        if (m_fmt->oformat->flags & AVFMT_GLOBALHEADER)
            m_enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;  // SPS/PPS in the avcC box
        if (av_opt_set(m_enc->priv_data, "preset", "veryfast", 0) < 0 ||
            av_opt_set(m_enc->priv_data, "crf", std::to_string(crf).c_str(), 0) < 0)
            return makeError("mp4: libx264 rejected an option");
        if ((err = avcodec_open2(m_enc, codec, nullptr)) < 0)
            return makeError(
                fmt::format("mp4: open x264 at {}x{}: {}", m_w, m_h, detail::avErrorText(err)));
        m_stream = avformat_new_stream(m_fmt, nullptr);
        if (!m_stream)
            return makeError("mp4: out of memory");
        m_stream->time_base = m_enc->time_base;
        m_stream->avg_frame_rate = m_enc->framerate;
        if ((err = avcodec_parameters_from_context(m_stream->codecpar, m_enc)) < 0)
            return makeError("mp4: " + detail::avErrorText(err));
        if ((err = avio_open(&m_fmt->pb, m_path.c_str(), AVIO_FLAG_WRITE)) < 0)
            return makeError(
                fmt::format("mp4: cannot write '{}': {}", m_path, detail::avErrorText(err)));
        AVDictionary* opts = nullptr;
        av_dict_set(&opts, "movflags", "+faststart", 0);
        err = avformat_write_header(m_fmt, &opts);
        av_dict_free(&opts);
        if (err < 0)
            return makeError(fmt::format("mp4: '{}': {}", m_path, detail::avErrorText(err)));
        m_frame->format = AV_PIX_FMT_YUV420P;
        m_frame->width = m_w;
        m_frame->height = m_h;
        if (av_frame_get_buffer(m_frame, 0) < 0)
            return makeError("mp4: out of memory");
        m_sws = sws_getContext(m_w, m_h, AV_PIX_FMT_RGBA, m_w, m_h, AV_PIX_FMT_YUV420P,
                               SWS_BILINEAR, nullptr, nullptr, nullptr);
        if (!m_sws)
            return makeError("mp4: no RGBA to YUV420 conversion");
        return {};
    }

    Status write(const ImageRgba8& image) override {
        if (m_finished)
            return makeError("mp4: write after finish");
        if (image.width() != m_w || image.height() != m_h)
            return makeError(fmt::format("mp4: frame is {}x{}, the video {}x{}", image.width(),
                                         image.height(), m_w, m_h));
        if (av_frame_make_writable(m_frame) < 0)
            return makeError("mp4: out of memory");
        const uint8_t* src[1] = {image.data()};
        const int stride[1] = {4 * m_w};
        sws_scale(m_sws, src, stride, 0, m_h, m_frame->data, m_frame->linesize);
        m_frame->pts = m_next_pts++;
        return send(m_frame);
    }

    Status finish() override {
        if (m_finished)
            return {};
        m_finished = true;
        if (auto st = send(nullptr); !st)
            return st;
        int err = av_write_trailer(m_fmt);
        if (err < 0)
            return makeError(
                fmt::format("mp4: finishing '{}': {}", m_path, detail::avErrorText(err)));
        if ((err = avio_closep(&m_fmt->pb)) < 0)
            return makeError(
                fmt::format("mp4: closing '{}': {}", m_path, detail::avErrorText(err)));
        return {};
    }

private:
    Status send(AVFrame* frame) {
        int err = avcodec_send_frame(m_enc, frame);
        if (err < 0)
            return makeError("mp4: encode: " + detail::avErrorText(err));
        while (true) {
            err = avcodec_receive_packet(m_enc, m_pkt);
            if (err == detail::kAvErrorEagain || err == detail::kAvErrorEof)
                return {};
            if (err < 0)
                return makeError("mp4: encode: " + detail::avErrorText(err));
            av_packet_rescale_ts(m_pkt, m_enc->time_base, m_stream->time_base);
            m_pkt->stream_index = m_stream->index;
            err = av_interleaved_write_frame(m_fmt, m_pkt);  // takes the packet's data
            if (err < 0)
                return makeError(
                    fmt::format("mp4: writing '{}': {}", m_path, detail::avErrorText(err)));
        }
    }

    std::string m_path;
    int m_w;
    int m_h;
    AVFormatContext* m_fmt = nullptr;
    AVCodecContext* m_enc = nullptr;
    AVStream* m_stream = nullptr;
    AVFrame* m_frame = nullptr;
    AVPacket* m_pkt = nullptr;
    SwsContext* m_sws = nullptr;
    int64_t m_next_pts = 0;
    bool m_finished = false;
};

}  // namespace

Expected<std::unique_ptr<Mp4Writer>> Mp4Writer::open(const std::string& path, int width, int height,
                                                     int fps, int crf) {
    if (width < 16 || height < 16 || width > 8192 || height > 8192 || width % 2 || height % 2)
        return makeError(
            fmt::format("mp4: frame size {}x{} must be even and within 16..8192", width, height));
    if (fps < 1 || fps > 1000)
        return makeError(fmt::format("mp4: frame rate {} must be within 1..1000", fps));
    if (crf < 0 || crf > 51)
        return makeError(fmt::format("mp4: crf {} must be within 0..51", crf));
    detail::quietFfmpegLog();
    auto w = std::make_unique<AvMp4Writer>(path, width, height);
    if (auto st = w->init(fps, crf); !st)
        return makeError(st.error());
    return std::unique_ptr<Mp4Writer>(std::move(w));
}

Expected<VideoFileInfo> probeVideoFile(const std::string& path) {
    detail::quietFfmpegLog();
    AVFormatContext* fmt_ctx = nullptr;
    int err = avformat_open_input(&fmt_ctx, path.c_str(), nullptr, nullptr);
    if (err < 0)
        return makeError(
            fmt::format("'{}': not a readable video file: {}", path, detail::avErrorText(err)));
    struct Closer {
        AVFormatContext** c;
        ~Closer() { avformat_close_input(c); }
    } closer{&fmt_ctx};
    if ((err = avformat_find_stream_info(fmt_ctx, nullptr)) < 0)
        return makeError(fmt::format("'{}': {}", path, detail::avErrorText(err)));
    const int index = av_find_best_stream(fmt_ctx, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (index < 0)
        return makeError(fmt::format("'{}': no video stream", path));
    const AVStream* st = fmt_ctx->streams[index];
    VideoFileInfo info;
    info.format_name = fmt_ctx->iformat->name;
    info.codec_name = avcodec_get_name(st->codecpar->codec_id);
    if (const char* p = avcodec_profile_name(st->codecpar->codec_id, st->codecpar->profile))
        info.profile = p;
    info.width = st->codecpar->width;
    info.height = st->codecpar->height;
    if (st->avg_frame_rate.den > 0)
        info.fps = av_q2d(st->avg_frame_rate);
    AVPacket* pkt = av_packet_alloc();
    if (!pkt)
        return makeError("out of memory");
    while ((err = av_read_frame(fmt_ctx, pkt)) >= 0) {
        if (pkt->stream_index == index) {
            ++info.frames;
            if (pkt->flags & AV_PKT_FLAG_KEY)
                ++info.key_frames;
        }
        av_packet_unref(pkt);
    }
    av_packet_free(&pkt);
    if (err != detail::kAvErrorEof)
        return makeError(fmt::format("'{}': reading packets: {}", path, detail::avErrorText(err)));
    return info;
}

}  // namespace qvr
