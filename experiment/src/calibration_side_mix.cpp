// The calibration's side mixes (calibration_side_mix.h).
#include "calibration_side_mix.h"

namespace qvr::experiment {

// The server's frame `step` (its encoders carry on from the frame before).
Status SideMix::server(int step) {
    const auto [head, plan] = view(step);
    for (int eye = 0; eye < 2; ++eye)
        for (int li = 0; li < 2; ++li) {
            const LayerKind kind = li == 0 ? LayerKind::kMiddle : LayerKind::kOuter;
            if (auto st = renderLayer(m_r, m_profile, plan, head, static_cast<Eye>(eye), kind,
                                      m_image, CameraOptions{}, LayerHoles{.enabled = true});
                !st)
                return makeError("layer render: " + st.error());
            auto& enc = m_encoders[static_cast<size_t>(eye * 2 + li)];
            if (!enc) {
                auto made = makeVideoEncoder(m_codec);
                if (!made)
                    return makeError("codec: " + made.error());
                enc = std::move(*made);
            }
            auto out = enc->encode(m_image);
            if (!out)
                return makeError("encode: " + out.error());
            m_canvas_px[static_cast<size_t>(eye * 2 + li)] =
                double(enc->canvasWidth()) * double(enc->canvasHeight());
            if (m_recording)
                m_streams[static_cast<size_t>(eye * 2 + li)].push_back(std::move(out->bytes));
        }
    return {};
}

// The headset's frame `step`: its streams are the server's first kStreamFrames frames,
// coded once (the first call), then decoded in order, key frame first, round and round.
Status SideMix::headset(int step) {
    if (m_streams[0].empty()) {
        m_recording = true;
        for (int k = 0; k < kStreamFrames; ++k)
            if (auto st = server(k); !st)
                return st;
        m_recording = false;
        m_encoders = {};
    }
    const auto [head, plan] = view(step);
    auto frame = std::make_shared<LayerFrame>();
    frame->plan = plan;
    frame->render_pose = head;
    for (int eye = 0; eye < 2; ++eye) {
        EyeLayerImages& imgs = frame->eyes[static_cast<size_t>(eye)];
        if (auto st = renderLayer(m_r, m_profile, plan, head, static_cast<Eye>(eye),
                                  LayerKind::kFovea, imgs.fovea);
            !st)
            return makeError("fovea render: " + st.error());
        for (int li = 0; li < 2; ++li) {
            const size_t sid = static_cast<size_t>(eye * 2 + li);
            auto& dec = m_decoders[sid];
            if (!dec) {
                auto made = makeVideoDecoder(m_codec);
                if (!made)
                    return makeError("codec: " + made.error());
                dec = std::move(*made);
            }
            const auto& packets = m_streams[sid];
            const auto t0 = CalibrationClock::now();
            auto img = dec->decode(packets[static_cast<size_t>(m_next_packet) % packets.size()]);
            const double ms = msSince(t0);
            if (!img)
                return makeError("decode: " + img.error());
            if (m_decodes)
                m_decodes->push_back({ms, m_canvas_px[sid], 0.0});
            (li == 0 ? imgs.middle : imgs.outer) = std::move(*img);
        }
    }
    ++m_next_packet;
    auto rep = m_compositor.present(frame, head, m_display);
    if (!rep)
        return makeError("UCA: " + rep.error());
    return {};
}

}  // namespace qvr::experiment
