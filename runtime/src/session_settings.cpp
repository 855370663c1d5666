// Server and headset configurations from the command line's settings (session_settings.h).
#include "qvr/runtime/session_settings.h"

#include "qvr/core/link_spec.h"
#include "qvr/runtime/session.h"

namespace qvr::runtime {

namespace {

// What both sides read first: the pre-shared key, then the display profile.
struct KeyAndProfile {
    net::PresharedKey key;
    HmdProfile profile;
};
Expected<KeyAndProfile> keyAndProfile(const std::string& key_text, const std::string& key_file,
                                      const std::string& profile_name) {
    auto key = keyFromOptions(key_text, key_file);
    if (!key)
        return makeError(key.error());
    auto profile = runtimeProfileByName(profile_name);
    if (!profile)
        return makeError("--profile: " + profile.error());
    return KeyAndProfile{*key, *profile};
}

}  // namespace

Expected<RenderServerConfig> renderServerConfig(const ServerSettings& s) {
    auto shared = keyAndProfile(s.key, s.key_file, s.profile);
    if (!shared)
        return makeError(shared.error());
    auto link = loadLinkSpec(s.net);
    if (!link)
        return makeError("--net: " + link.error());
    RenderServerConfig cfg;
    cfg.net.bind_address = s.bind;
    cfg.net.port = s.port;
    cfg.net.key = shared->key;
    cfg.net.link = *link;
    cfg.profile = shared->profile;
    cfg.codec.backend = s.codec;
    cfg.core = s.core;
    cfg.workers = s.workers;
    cfg.admission.min_fps = s.min_fps;
    if (s.frame_cost_ms > 0.0)
        cfg.admission.frame_cost_ms = s.frame_cost_ms;
    cfg.one_pass_periphery = s.one_pass_periphery;
    cfg.holes.enabled = !s.no_holes;
    auto share = parseSharePeripheryMode(s.share_periphery);
    if (!share)
        return makeError("--share-periphery: " + share.error());
    cfg.share_periphery.mode = *share;
    if (!s.keep_frame_records)
        cfg.max_frame_records = 0;
    GlRendererOptions gl;
    gl.lod_error_px = s.lod_px;
    cfg.renderer = glRendererFactory(gl);
    return cfg;
}

Expected<HeadsetConfig> headsetConfig(const HeadsetSettings& s) {
    auto shared = keyAndProfile(s.key, s.key_file, s.profile);
    if (!shared)
        return makeError(shared.error());
    auto design = parseDesign(s.design, DesignScope::Runtime);
    if (!design)
        return makeError("--design: " + design.error());
    HeadsetConfig hc;
    hc.design = design->design;
    hc.fixed_e1_deg = design->fixed_e1_deg;
    hc.profile = shared->profile;
    hc.codec.backend = s.codec;
    hc.host = s.host;
    hc.port = s.port;
    hc.key = shared->key;
    hc.frames = s.frames;
    hc.core = s.core;
    GlRendererOptions gl;
    gl.lod_error_px = s.lod_px;
    hc.renderer = glRendererFactory(gl);
    return hc;
}

}  // namespace qvr::runtime
