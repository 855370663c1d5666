// `qvr server`: the render server (paper §3.2, Fig. 7) on its own: renders and streams the middle
// and outer layers each headset requests, after a pre-shared-key handshake; loopback by default.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <fmt/format.h>
#include "cli_parse.h"
#include "commands.h"
#include "qvr/codec/video_codec.h"
#include "qvr/net/agones_sdk.h"
#include "qvr/net/link_emulator.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/session_outputs.h"
#include "qvr/scene/scene_loader.h"

namespace qvr::cli {

namespace {

using namespace qvr::runtime;

std::atomic<bool> g_server_stop{false};

void onServerSignal(int) {
    g_server_stop = true;
}

struct ServerCmdOptions {
    std::string bind = "127.0.0.1";
    uint16_t port = 7400;
    std::string key;
    std::string key_file;
    std::string scene = "builtin:room";
    std::string profile = "default";
    std::string net = "none";
    std::string codec = "x264";
    int core = -1;
    double duration_s = 0.0;
    std::string stats_json;
    std::string stamps_csv;
    std::string frames_csv;
    bool one_pass_periphery = false;
    bool no_holes = false;
    float lod_px = 1.0f;
    bool agones = false;  // report Ready / Health / Shutdown to Agones' SDK sidecar
};

// The server's settings from the options (each checked when parsed); an error when the key,
// the scene or the stamps file cannot be had.
Expected<RenderServerConfig> serverConfig(const ServerCmdOptions& o, StampsFile& stamps) {
    auto key = keyFromOptions(o.key, o.key_file);
    if (!key)
        return makeError(key.error());
    auto profile = runtimeProfileByName(o.profile);
    if (!profile)
        return makeError("--profile: " + profile.error());
    auto link = qvr::loadLinkSpec(o.net);
    if (!link)
        return makeError("--net: " + link.error());
    RenderServerConfig cfg;
    cfg.net.bind_address = o.bind;
    cfg.net.port = o.port;
    cfg.net.key = *key;
    cfg.net.link = *link;
    cfg.net.on_refusal = [](const std::string& why) {
        std::fprintf(stderr, "qvr server: %s\n", why.c_str());
    };
    cfg.profile = *profile;
    cfg.codec.backend = o.codec;
    cfg.core = o.core;
    cfg.one_pass_periphery = o.one_pass_periphery;
    cfg.holes.enabled = !o.no_holes;
    if (o.frames_csv.empty())
        cfg.max_frame_records = 0;
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    cfg.renderer = glRendererFactory(gl);
    if (!o.stamps_csv.empty())
        if (Status st = attachServerStampsCsv(o.stamps_csv, cfg, stamps); !st)
            return makeError("--stamps-csv: " + st.error());
    return cfg;
}

// Serves until SIGINT/SIGTERM, or until `duration_s` seconds have passed when it is above 0.
void serveUntilStopped(double duration_s) {
    std::signal(SIGINT, onServerSignal);
    std::signal(SIGTERM, onServerSignal);
    const auto t0 = std::chrono::steady_clock::now();
    while (!g_server_stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (duration_s > 0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >
                duration_s)
            break;
    }
}

// --agones (docs/DEPLOY.md): Health pings every kAgonesHealthPeriodMs while the server serves,
// shorter than the fleet's health period (deploy/agones; scripts/check_agones.py checks it).
constexpr int kAgonesHealthPeriodMs = 2000;

// The SDK sidecar's address from AGONES_SDK_HTTP_PORT, checked before any work.
Expected<net::AgonesSdkOptions> agonesOptions() {
    auto port = net::agonesHttpPort(std::getenv("AGONES_SDK_HTTP_PORT"));
    if (!port)
        return makeError("--agones: " + port.error());
    net::AgonesSdkOptions options;
    options.port = *port;
    return options;
}

// Serves until stopped; with the SDK, Ready first (the server takes headsets only once the
// fleet may allocate it), Health all along, Shutdown after.
Status serveWithLifecycle(const ServerCmdOptions& o, std::optional<net::AgonesSdk>& sdk) {
    if (!sdk) {
        serveUntilStopped(o.duration_s);
        return Status::success();
    }
    if (Status st = sdk->ready(); !st)
        return st;
    fmt::print("qvr server: Agones SDK: Ready sent (port {})\n", sdk->options().port);
    std::fflush(stdout);
    {
        net::AgonesHealthPinger pinger(*sdk, kAgonesHealthPeriodMs);
        serveUntilStopped(o.duration_s);
    }
    if (Status st = sdk->shutdown(); !st)
        std::fprintf(stderr, "qvr server: %s\n", st.error().c_str());
    return Status::success();
}

int runServer(const ServerCmdOptions& o) {
    // Pin the whole process before any work: threads made from here on (asio, the render
    // thread, llvmpipe's rasterizers, x264) inherit the mask.
    if (o.core >= 0) {
        if (auto st = pinCurrentThread(o.core); !st) {
            std::fprintf(stderr, "qvr server: --core: %s\n", st.error().c_str());
            return 2;
        }
    }
    std::optional<net::AgonesSdk> sdk;
    if (o.agones) {
        auto options = agonesOptions();
        if (!options) {
            std::fprintf(stderr, "qvr server: %s\n", options.error().c_str());
            return 2;
        }
        sdk.emplace(*options);
    }
    StampsFile stamps(nullptr, std::fclose);
    auto cfg = serverConfig(o, stamps);
    if (!cfg) {
        std::fprintf(stderr, "qvr server: %s\n", cfg.error().c_str());
        return 2;
    }
    auto scene = loadScene(o.scene);
    if (!scene) {
        std::fprintf(stderr, "qvr server: %s\n", scene.error().c_str());
        return 2;
    }
    auto server = RenderServer::start(*cfg, std::make_shared<const Scene>(std::move(*scene)));
    if (!server) {
        std::fprintf(stderr, "qvr server: %s\n", server.error().c_str());
        return 1;
    }
    fmt::print("qvr server: listening on {}:{} ({}x{} per eye, link {}); Ctrl-C stops\n", o.bind,
               (*server)->port(), cfg->profile.width_px, cfg->profile.height_px, o.net);
    std::fflush(stdout);
    const Status served = serveWithLifecycle(o, sdk);
    // Stop first (the frame in flight finishes, the render thread is joined), then read: the
    // stats and the frames CSV then describe the same frames, however the server was ended.
    (*server)->stop();
    const RenderServerStats s = (*server)->stats();
    const std::vector<ServerFrameRecord> frame_records = (*server)->frameRecords();
    if (stamps && std::fflush(stamps.get()) != 0)
        std::fprintf(stderr, "qvr server: error writing '%s'\n", o.stamps_csv.c_str());
    if (Status st = writeServerOutputs({o.stats_json, o.frames_csv}, s, o.core, frame_records);
        !st) {
        std::fprintf(stderr, "qvr server: %s\n", st.error().c_str());
        return 1;
    }
    fmt::print("{}", serverStatsReport(s));
    if (!served) {
        std::fprintf(stderr, "qvr server: %s\n", served.error().c_str());
        return 1;
    }
    return 0;
}

}  // namespace

static Registered registerServer(CLI::App& app) {
    auto o = std::make_shared<ServerCmdOptions>();
    CLI::App* cmd = app.add_subcommand("server", "The render server: streams periphery layers");
    cmd->add_option("--bind", o->bind, "Address to listen on (loopback unless changed)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                return isIpAddress(text) ? std::string()
                                         : "'" + text + "' is not an IPv4 or IPv6 address";
            },
            "IP", "IP_ADDRESS"))
        ->capture_default_str();
    cmd->add_option("--port", o->port, "TCP port (0: any)")->capture_default_str();
    addKeyOptions(cmd, o->key, o->key_file);
    cmd->add_option("--scene", o->scene, "Scene")->capture_default_str();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime);
    addLinkOption(cmd, o->net);
    addCodecOption(cmd, o->codec);
    addCoreOption(cmd, o->core, "Pin the server (all its threads) to this core (-1: no)");
    addLodOption(cmd, o->lod_px);
    cmd->add_option("--stats-json", o->stats_json, "Write the server's counters here on exit")
        ->check(writableFile());
    cmd->add_option("--stamps-csv", o->stamps_csv,
                    "Write per-layer render/encode/send stamps (steady clock ns) here")
        ->check(writableFile());
    cmd->add_option("--frames-csv", o->frames_csv,
                    "Write one row per served frame (per-layer render, read-back, encode, send) "
                    "here on exit")
        ->check(writableFile());
    cmd->add_flag("--no-holes", o->no_holes,
                  "Draw every periphery layer whole, also where the compositor takes a finer "
                  "layer");
    cmd->add_flag("--one-pass-periphery", o->one_pass_periphery,
                  "Render middle and outer in one geometry pass per eye (pays when vertex-bound)");
    cmd->add_flag("--agones", o->agones,
                  "Report Ready, Health and Shutdown to Agones' SDK sidecar at "
                  "localhost:$AGONES_SDK_HTTP_PORT (docs/DEPLOY.md)");
    cmd->add_option("--duration-s", o->duration_s, "Stop after this many seconds (0: on signal)")
        ->check(finiteRange(0.0, kMaxDurationS))
        ->capture_default_str();
    return {cmd, [o] { return runServer(*o); }};
}

QVR_REGISTER_COMMAND(90, registerServer);

}  // namespace qvr::cli
