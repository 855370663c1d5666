// Shared set-up of runtime sessions: profile, traces, key.
#include "qvr/runtime/session.h"

#include <fstream>

#include <fmt/format.h>

#include "qvr/render/camera.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/trace/head_motion.h"

namespace qvr::runtime {

Expected<HmdProfile> runtimeProfileByName(const std::string& name) {
    if (name == "run" || name == "small") {
        HmdProfile p = defaultHmdProfile();
        p.name = name == "run" ? "run-480x540" : "small-320x360";
        p.width_px = name == "run" ? 480 : 320;
        p.height_px = name == "run" ? 540 : 360;
        return p;
    }
    return hmdProfileByName(name);
}

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Pose spawnPose(const Scene& scene) {
    return scene.spawns.empty() ? Pose{} : poseFromSpawn(scene.spawns.front());
}

}  // namespace

Expected<HeadsetTraces> makeTraces(const std::string& motion, const std::string& gaze,
                                   const Scene& scene, double refresh_hz, int frames,
                                   uint64_t seed) {
    HeadsetTraces t;
    const Pose spawn = spawnPose(scene);
    if (motion == "still") {
        t.motion.samples.push_back({0.0, spawn});
    } else if (endsWith(motion, ".csv")) {
        auto p = loadPoseCsv(motion);
        if (!p)
            return makeError(p.error());
        t.motion = std::move(*p);
    } else {
        const std::string path = motion == "default" ? defaultBvhPath() : motion;
        auto bvh = loadBvhFile(path);
        if (!bvh)
            return makeError(fmt::format(
                "{}{}", bvh.error(),
                motion == "default" ? " (install the Debian package assimp-testmodels)" : ""));
        HeadMotionOptions o;
        o.rate_hz = refresh_hz;
        o.smooth_sigma_ms = 10.0;
        // The trace's floor goes to the spawn's floor: spawn points are eye positions.
        const float eye_height_m = 1.6f;
        o.origin_m = {spawn.position_m.x, spawn.position_m.y - eye_height_m, spawn.position_m.z};
        o.yaw_deg = scene.spawns.empty() ? 0.0 : scene.spawns.front().yaw_deg;
        auto trace = headTraceFromBvh(*bvh, o);
        if (!trace)
            return makeError(path + ": " + trace.error());
        t.motion = std::move(*trace);
    }
    if (gaze == "center") {
        t.gaze.samples.push_back({0.0, Gaze{}});
    } else if (gaze == "model") {
        GazeModelConfig cfg;
        const int samples =
            static_cast<int>(double(std::max(frames, 1)) / refresh_hz * cfg.sample_rate_hz) + 2;
        auto g = generateGaze(cfg, seed, samples);
        if (!g)
            return makeError(g.error());
        t.gaze = std::move(*g);
    } else {
        auto g = loadGazeCsv(gaze);
        if (!g)
            return makeError(g.error());
        t.gaze = std::move(*g);
    }
    if (t.motion.samples.empty() || t.gaze.samples.empty())
        return makeError("empty head-motion or gaze trace");
    return t;
}

void playAhead(HeadsetTraces& traces, double ms) {
    for (PoseSample& s : traces.motion.samples)
        s.t_ms -= ms;
    for (GazeSample& s : traces.gaze.samples)
        s.t_ms -= ms;
    for (GazeEvent& e : traces.gaze.events)
        e.start_ms -= ms;
}

Expected<HeadsetInputs> loadHeadsetInputs(const std::string& scene, const std::string& motion,
                                          const std::string& gaze, double refresh_hz, int frames,
                                          uint64_t seed) {
    auto loaded = loadScene(scene);
    if (!loaded)
        return makeError(loaded.error());
    HeadsetInputs in;
    in.scene = std::make_shared<const Scene>(std::move(*loaded));
    in.bvh = std::make_shared<const TriangleBvh>(*in.scene);
    auto traces = makeTraces(motion, gaze, *in.scene, refresh_hz, frames, seed);
    if (!traces)
        return makeError(traces.error());
    in.traces = std::move(*traces);
    return in;
}

Expected<net::PresharedKey> keyFromOptions(const std::string& key, const std::string& key_file) {
    if (key.empty() == key_file.empty())
        return makeError("give exactly one of --key or --key-file");
    std::string text = key;
    if (!key_file.empty()) {
        std::ifstream in(key_file);
        if (!in)
            return makeError("cannot read key file '" + key_file + "'");
        std::getline(in, text);
        while (!text.empty() && (text.back() == '\r' || text.back() == ' '))
            text.pop_back();
    }
    if (text.rfind("pass:", 0) == 0)
        return net::PresharedKey::fromPassphrase(text.substr(5));
    return net::PresharedKey::fromHex(text);
}

}  // namespace qvr::runtime
