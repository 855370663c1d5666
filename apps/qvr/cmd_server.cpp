// `qvr server`: the render server (paper §3.2, Fig. 7) on its own: renders and streams the middle
// and outer layers each headset requests, after a pre-shared-key handshake; loopback by default.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/net/agones_sdk.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/serve_loop.h"
#include "qvr/runtime/session_outputs.h"
#include "qvr/runtime/session_settings.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/sim/hardware.h"

namespace qvr::cli {

namespace {

using namespace qvr::runtime;

std::atomic<bool> g_server_stop{false};

void onServerSignal(int) {
    g_server_stop = true;
}

struct ServerCmdOptions {
    ServerSettings settings;
    std::string scene = "builtin:room";
    double duration_s = 0.0;
    std::string calibration;  // hardware file whose server frame time admission starts from
    std::string stats_json;
    std::string stamps_csv;
    std::string frames_csv;
    bool agones = false;  // report Ready / Health / Shutdown to Agones' SDK sidecar
};

// The server's settings from the options (each checked when parsed); an error when the key,
// the profile, the link or the stamps file cannot be had.
Expected<RenderServerConfig> serverConfig(ServerCmdOptions o, StampsFile& stamps) {
    o.settings.keep_frame_records = !o.frames_csv.empty();
    if (!o.calibration.empty()) {
        auto hw = loadHardwareConfig(o.calibration, 500.0);
        if (!hw || hw->runtime.speed_reference_server_ms <= 0.0)
            return makeError("--calibration: " +
                             (hw ? "no runtime.speed_reference_server_ms in '" + o.calibration + "'"
                                 : hw.error()));
        o.settings.frame_cost_ms = hw->runtime.speed_reference_server_ms;
    }
    auto cfg = renderServerConfig(o.settings);
    if (!cfg)
        return cfg;
    cfg->net.on_refusal = [](const std::string& why) { fail("server", why, 0); };
    if (!o.stamps_csv.empty())
        if (Status st = attachServerStampsCsv(o.stamps_csv, *cfg, stamps); !st)
            return makeError("--stamps-csv: " + st.error());
    return cfg;
}

// Serves until SIGINT/SIGTERM or --duration-s; with --agones, the fleet's lifecycle.
Status serve(const ServerCmdOptions& o, net::AgonesSdk* sdk) {
    std::signal(SIGINT, onServerSignal);
    std::signal(SIGTERM, onServerSignal);
    ServeEvents events;
    events.ready_sent = [](uint16_t port) {
        fmt::print("qvr server: Agones SDK: Ready sent (port {})\n", port);
        std::fflush(stdout);
    };
    events.shutdown_failed = [](const std::string& why) { fail("server", why, 0); };
    return serveUntilStopped(g_server_stop, o.duration_s, sdk, events);
}

int runServer(const ServerCmdOptions& o) {
    // Pin the whole process before any work: threads made from here on (asio, the render
    // thread, llvmpipe's rasterizers, x264) inherit the mask.
    if (o.settings.core >= 0)
        if (auto st = pinCurrentThread(o.settings.core); !st)
            return fail("server", "--core: " + st.error(), 2);
    std::optional<net::AgonesSdk> sdk;
    if (o.agones) {
        auto options = agonesSdkOptions(std::getenv("AGONES_SDK_HTTP_PORT"));
        if (!options)
            return fail("server", options.error(), 2);
        sdk.emplace(*options);
    }
    StampsFile stamps(nullptr, std::fclose);
    auto cfg = serverConfig(o, stamps);
    if (!cfg)
        return fail("server", cfg.error(), 2);
    auto scene = loadScene(o.scene);
    if (!scene)
        return fail("server", scene.error(), 2);
    auto server = RenderServer::start(*cfg, std::make_shared<const Scene>(std::move(*scene)));
    if (!server)
        return fail("server", server.error(), 1);
    fmt::print("qvr server: listening on {}:{} ({}x{} per eye, link {}); Ctrl-C stops\n",
               o.settings.bind, (*server)->port(), cfg->profile.width_px, cfg->profile.height_px,
               o.settings.net);
    std::fflush(stdout);
    const Status served = serve(o, sdk ? &*sdk : nullptr);
    // Stop first (the frame in flight finishes, the render thread is joined), then read: the
    // stats and the frames CSV then describe the same frames, however the server was ended.
    (*server)->stop();
    const RenderServerStats s = (*server)->stats();
    const std::vector<ServerFrameRecord> frame_records = (*server)->frameRecords();
    if (stamps && std::fflush(stamps.get()) != 0)
        std::fprintf(stderr, "qvr server: error writing '%s'\n", o.stamps_csv.c_str());
    if (Status st =
            writeServerOutputs({o.stats_json, o.frames_csv}, s, o.settings.core, frame_records);
        !st)
        return fail("server", st.error(), 1);
    fmt::print("{}", serverStatsReport(s));
    if (!served)
        return fail("server", served.error(), 1);
    return 0;
}

}  // namespace

static Registered registerServer(CLI::App& app) {
    auto o = std::make_shared<ServerCmdOptions>();
    CLI::App* cmd = app.add_subcommand("server", "The render server: streams periphery layers");
    cmd->add_option("--bind", o->settings.bind, "Address to listen on (loopback unless changed)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                return isIpAddress(text) ? std::string()
                                         : "'" + text + "' is not an IPv4 or IPv6 address";
            },
            "IP", "IP_ADDRESS"))
        ->capture_default_str();
    cmd->add_option("--port", o->settings.port, "TCP port (0: any)")->capture_default_str();
    addKeyOptions(cmd, o->settings.key, o->settings.key_file);
    cmd->add_option("--scene", o->scene, "Scene")->capture_default_str();
    addProfileOption(cmd, o->settings.profile, ProfileNames::kRuntime);
    addLinkOption(cmd, o->settings.net);
    addCodecOption(cmd, o->settings.codec);
    addCoreOption(cmd, o->settings.core, "Pin the server (all its threads) to this core (-1: no)");
    addLodOption(cmd, o->settings.lod_px);
    addInt(cmd, "--workers", o->settings.workers,
           "Render workers (0: one per core the server may use; 1 with --core)", 0, 64);
    addFinite(cmd, "--min-fps", o->settings.min_fps,
              "Refuse a headset that would take the admitted ones below this frame rate (0: off; "
              "docs/RUNTIME.md)",
              0.0, 1000.0);
    cmd->add_option("--calibration", o->calibration,
                    "Hardware file (qvr calibrate) whose server frame time admission starts from")
        ->check(readableFile());
    cmd->add_option("--stats-json", o->stats_json, "Write the server's counters here on exit")
        ->check(writableFile());
    cmd->add_option("--stamps-csv", o->stamps_csv,
                    "Write per-layer render/encode/send stamps (steady clock ns) here")
        ->check(writableFile());
    cmd->add_option("--frames-csv", o->frames_csv,
                    "Write one row per served frame (per-layer render, read-back, encode, send) "
                    "here on exit")
        ->check(writableFile());
    addPeripheryPassFlags(cmd, o->settings.one_pass_periphery, o->settings.no_holes);
    addSharePeripheryOption(cmd, o->settings.share_periphery);
    cmd->add_flag("--agones", o->agones,
                  "Report Ready, Health and Shutdown to Agones' SDK sidecar at "
                  "localhost:$AGONES_SDK_HTTP_PORT (docs/DEPLOY.md)");
    addFinite(cmd, "--duration-s", o->duration_s, "Stop after this many seconds (0: on signal)",
              0.0, kMaxDurationS);
    return {cmd, [o] { return runServer(*o); }};
}

QVR_REGISTER_COMMAND(90, registerServer);

}  // namespace qvr::cli
