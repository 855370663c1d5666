// `qvr corun-load`: the child process CoRunLoad starts (corun_load.h), one side's frames beside
// the calibration's measured frames, or the speed probe.
#include <poll.h>
#include <unistd.h>
#include <cstdio>
#include <memory>
#include <optional>

#include "calibration_side_mix.h"
#include "qvr/experiment/calibration.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"

namespace qvr::experiment {

namespace {

// What the child's frames run on: the calibration's scene, renderer and traces.
struct LoadSetup {
    HmdProfile profile;
    runtime::HeadsetInputs inputs;
    std::unique_ptr<Renderer> renderer;
};

// Pinned to o.core, the scene loaded and uploaded; a message on stdout (the parent's error) if not.
std::unique_ptr<LoadSetup> setUpLoad(const CalibrateOptions& o) {
    using namespace qvr::runtime;
    if (auto st = pinCurrentThread(o.core); !st) {
        std::printf("%s\n", st.error().c_str());
        return nullptr;
    }
    auto profile = runtimeProfileByName(o.profile);
    auto inputs = profile
                      ? loadHeadsetInputs(o.scene, "default", "model", profile->refresh_hz, 400, 7)
                      : Expected<HeadsetInputs>(makeError(profile.error()));
    if (!inputs) {
        std::printf("%s\n", inputs.error().c_str());
        return nullptr;
    }
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    auto renderer = glRendererFactory(gl)();
    if (!renderer || !(*renderer)->upload(*inputs->scene)) {
        std::printf("%s\n", renderer ? "cannot upload the scene" : renderer.error().c_str());
        return nullptr;
    }
    return std::make_unique<LoadSetup>(
        LoadSetup{std::move(*profile), std::move(*inputs), std::move(*renderer)});
}

// The speed probe (SpeedProbe): one probe per "p" line, its medians on one line.
int serveSpeedProbes(SideMix& side) {
    if (auto st = side.headset(0); !st) {  // shaders compiled, the headset's streams coded
        std::printf("%s\n", st.error().c_str());
        return 1;
    }
    std::printf("ready\n");
    std::fflush(stdout);
    for (char c = 0; ::read(STDIN_FILENO, &c, 1) == 1;) {
        if (c != 'p')
            continue;
        auto sample = probeSpeed(side);
        if (!sample) {
            std::printf("%s\n", sample.error().c_str());
            return 1;
        }
        std::printf("%.6f %.6f\n", sample->headset_ms, sample->server_ms);
        std::fflush(stdout);
    }
    return 0;  // the parent is done
}

// One side's frames while told to be busy ("1"), none while told to pause ("0").
int serveLoad(SideMix& side, bool server) {
    int step = 0;
    auto frame = [&] { return server ? side.server(step++) : side.headset(step++); };
    // The first frame before "ready": shaders compiled, the headset's streams coded.
    if (auto st = frame(); !st) {
        std::printf("%s\n", st.error().c_str());
        return 1;
    }
    std::printf("ready\n");
    std::fflush(stdout);
    bool busy = false;
    bool answer = false;
    for (;;) {
        pollfd pfd{STDIN_FILENO, POLLIN, 0};
        const int n = ::poll(&pfd, 1, busy ? 0 : 100);
        if (n > 0) {
            char c = 0;
            if (::read(STDIN_FILENO, &c, 1) != 1)
                return 0;  // the parent is done
            if (c == '0' || c == '1') {
                busy = c == '1';
                answer = true;
            }
        }
        if (busy) {
            if (auto st = frame(); !st)
                return 1;
        }
        if (answer) {  // after the first frame when busy: the load is under way
            std::printf("k");
            std::fflush(stdout);
            answer = false;
        }
    }
}

}  // namespace

int runCoRunLoad(const CalibrateOptions& o, const std::string& mix) {
    auto setup = setUpLoad(o);
    if (!setup)
        return 2;
    CodecConfig codec;
    codec.backend = o.codec;
    SideMix side(*setup->renderer, setup->profile, setup->inputs, codec);
    if (mix == "probe")
        return serveSpeedProbes(side);
    return serveLoad(side, mix == "server");
}

}  // namespace qvr::experiment
