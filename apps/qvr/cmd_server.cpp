// `qvr server`: the render server (paper §3.2, Fig. 7) on its own: renders and streams the middle
// and outer layers each headset requests, after a pre-shared-key handshake; loopback by default.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/codec/video_codec.h"
#include "qvr/net/agones_sdk.h"
#include "qvr/net/link_emulator.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/chrome_trace.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"
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
    std::string bind = "127.0.0.1";
    uint16_t port = 7400;
    std::string key;
    std::string key_file;
    std::string scene = "builtin:room";
    std::string profile = "default";
    std::string net = "none";
    std::string codec = "x264";
    int core = -1;
    int workers = 0;
    double min_fps = 0.0;
    std::string calibration;
    double duration_s = 0.0;
    std::string stats_json;
    std::string stamps_csv;
    std::string frames_csv;
    bool one_pass_periphery = false;
    bool no_holes = false;
    float lod_px = 1.0f;
    bool agones = false;  // report Ready / Health / Shutdown to Agones' SDK sidecar
};

using StampsFile = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

// Per-frame stamps for timelines (qvr run's trace.json): one line per layer sent, on this
// process's steady clock; bounded so a long-running server cannot fill the disk.
Status attachStampsCsv(const std::string& path, RenderServerConfig& cfg, StampsFile& stamps) {
    stamps.reset(std::fopen(path.c_str(), "w"));
    if (!stamps)
        return makeError("--stamps-csv: cannot write '" + path + "'");
    std::fputs(kServerStampsHeader, stamps.get());
    cfg.on_frame = [f = stamps.get(), lines = int64_t{0}](const ServerFrameStamps& st) mutable {
        for (const ServerFrameStamps::Layer& l : st.layers) {
            if (++lines > kMaxServerStampLines)
                return;
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{}\n", st.client, st.frame_id,
                       st.client_send_ns, st.queued_ns, st.start_ns, st.end_ns, l.stream_id,
                       l.render_start_ns, l.render_end_ns, l.encode_end_ns, l.sent_ns);
        }
        // Whole frames on disk: a client on this machine reads the file while we run.
        std::fflush(f);
    };
    return {};
}

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
    cfg.workers = o.workers;
    cfg.admission.min_fps = o.min_fps;
    if (!o.calibration.empty()) {
        auto hw = loadHardwareConfig(o.calibration, 500.0);
        if (!hw || hw->runtime.speed_reference_server_ms <= 0.0)
            return makeError("--calibration: " +
                             (hw ? "no runtime.speed_reference_server_ms in '" + o.calibration + "'"
                                 : hw.error()));
        cfg.admission.frame_cost_ms = hw->runtime.speed_reference_server_ms;
    }
    cfg.one_pass_periphery = o.one_pass_periphery;
    cfg.holes.enabled = !o.no_holes;
    if (o.frames_csv.empty())
        cfg.max_frame_records = 0;
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    cfg.renderer = glRendererFactory(gl);
    if (!o.stamps_csv.empty())
        if (Status st = attachStampsCsv(o.stamps_csv, cfg, stamps); !st)
            return makeError(st.error());
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

nlohmann::json serverStatsJson(const RenderServerStats& s, int core) {
    return {{"requests", s.requests},
            {"requests_dropped", s.requests_dropped},
            {"requests_invalid", s.requests_invalid},
            {"frames_rendered", s.frames_rendered},
            {"layers_rendered", s.layers_rendered},
            {"periphery_passes", s.periphery_passes},
            {"streams_sent", s.streams_sent},
            {"stream_send_failures", s.stream_send_failures},
            {"render_failures", s.render_failures},
            {"encode_failures", s.encode_failures},
            {"key_frame_requests", s.key_frame_requests},
            {"render_ms_total", s.render_ms_total},
            {"encode_ms_total", s.encode_ms_total},
            {"readback_ms_total", s.readback_ms_total},
            {"send_ms_total", s.send_ms_total},
            {"connections", s.net.connections},
            {"clients_accepted", s.net.clients_accepted},
            {"auth_failures", s.net.auth_failures},
            {"handshake_timeouts", s.net.handshake_timeouts},
            {"refused_full", s.net.refused_full},
            {"pending_evicted", s.net.pending_evicted},
            {"idle_timeouts", s.net.idle_timeouts},
            {"keepalives", s.net.keepalives},
            {"protocol_errors", s.net.protocol_errors},
            {"version_mismatches", s.net.version_mismatches},
            {"settings_refusals", s.net.settings_refusals},
            {"route_failures", s.net.route_failures},
            {"control_forged", s.net.control_forged},
            {"control_replayed", s.net.control_replayed},
            {"nacks", s.net.nacks},
            {"packets_retransmitted", s.net.packets_retransmitted},
            {"bytes_retransmitted", s.net.bytes_retransmitted},
            {"retransmissions_refused", s.net.retransmissions_refused},
            {"fec_frames", s.net.fec_frames},
            {"fec_parity_packets", s.net.fec_parity_packets},
            {"fec_parity_bytes", s.net.fec_parity_bytes},
            {"client_loss_ppm", s.net.client_loss_ppm},
            {"control_drops", s.net.control_drops.total()},
            {"link",
             {{"packets_in", s.net.link.packets_in},
              {"packets_delivered", s.net.link.packets_delivered},
              {"dropped_loss", s.net.link.dropped_loss},
              {"dropped_queue", s.net.link.dropped_queue},
              {"dropped_burst", s.net.link.dropped_burst},
              {"reordered", s.net.link.reordered},
              {"duplicated", s.net.link.duplicated},
              {"spiked", s.net.link.spiked}}},
            {"core", core}};
}

// One row per served frame: per-layer pixels, triangles, render, read-back, encode and send.
Status writeServerFramesCsv(const std::string& path,
                            const std::vector<ServerFrameRecord>& records) {
    std::ofstream f(path);
    f << "client,frame,e1_deg,received_ns,start_ns,done_ns";
    for (int sid = 0; sid < 4; ++sid)
        f << fmt::format(
            ",pixels{0},triangles{0},render_ms{0},readback_ms{0},encode_ms{0},"
            "send_ms{0},bytes{0}",
            sid);
    f << "\n";
    for (const ServerFrameRecord& r : records) {
        f << fmt::format("{},{},{:.3f},{},{},{}", r.client, r.frame_id, r.e1_deg, r.received_ns,
                         r.start_ns, r.done_ns);
        for (size_t sid = 0; sid < 4; ++sid)
            f << fmt::format(",{},{},{:.3f},{:.3f},{:.3f},{:.3f},{}", r.pixels[sid],
                             r.triangles[sid], r.render_ms[sid], r.readback_ms[sid],
                             r.encode_ms[sid], r.send_ms[sid], r.bytes[sid]);
        f << "\n";
    }
    if (!f)
        return makeError("cannot write '" + path + "'");
    return {};
}

void printServerStats(const RenderServerStats& s) {
    fmt::print(
        "qvr server: {} requests ({} dropped, {} invalid), {} frames, {} streams sent, {} auth "
        "failures, {} malformed control messages\n",
        s.requests, s.requests_dropped, s.requests_invalid, s.frames_rendered, s.streams_sent,
        s.net.auth_failures, s.net.control_drops.total());
    fmt::print(
        "qvr server: {} connections, {} sessions; {} handshake timeouts, {} idle timeouts, {} "
        "evicted, {} refused full, {} protocol errors, {} version / {} settings refusals, {} "
        "media ports unverified; {} forged / {} replayed control messages; {} NACKs, {} packets "
        "retransmitted\n",
        s.net.connections, s.net.clients_accepted, s.net.handshake_timeouts, s.net.idle_timeouts,
        s.net.pending_evicted, s.net.refused_full, s.net.protocol_errors, s.net.version_mismatches,
        s.net.settings_refusals, s.net.route_failures, s.net.control_forged, s.net.control_replayed,
        s.net.nacks, s.net.packets_retransmitted);
}

// Writes --stats-json and --frames-csv once the server has stopped.
int writeServerOutputs(const ServerCmdOptions& o, const RenderServerStats& s,
                       const std::vector<ServerFrameRecord>& frame_records) {
    if (!o.stats_json.empty()) {
        std::ofstream f(o.stats_json);
        nlohmann::json j = serverStatsJson(s, o.core);
        j.update(serverPoolJson(s));  // "workers", "admission", "sessions"
        f << j.dump(2) << "\n";
        if (!f) {
            std::fprintf(stderr, "qvr server: cannot write '%s'\n", o.stats_json.c_str());
            return 1;
        }
    }
    if (!o.frames_csv.empty()) {
        if (Status st = writeServerFramesCsv(o.frames_csv, frame_records); !st) {
            std::fprintf(stderr, "qvr server: %s\n", st.error().c_str());
            return 1;
        }
    }
    return 0;
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
    if (const int rc = writeServerOutputs(o, s, frame_records); rc != 0)
        return rc;
    printServerStats(s);
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
    cmd->add_option("--workers", o->workers,
                    "Render workers (0: one per core the server may use; 1 with --core)")
        ->check(CLI::Range(0, 64))
        ->capture_default_str();
    cmd->add_option("--min-fps", o->min_fps,
                    "Refuse a headset that would take the admitted ones below this frame rate "
                    "(0: off; docs/RUNTIME.md)")
        ->check(finiteRange(0.0, 1000.0))
        ->capture_default_str();
    cmd->add_option("--calibration", o->calibration,
                    "Hardware file (qvr calibrate) whose server frame time admission starts from")
        ->check(CLI::ExistingFile);
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
