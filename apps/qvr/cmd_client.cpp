// `qvr client`: the headset on its own (paper Fig. 4): head motion and gaze from traces, LIWC (or
// another design) picks e1, the fovea renders locally, the periphery comes from `qvr server`,
// UCA composes at the display rate; per-frame telemetry and a summary are written.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/codec/video_codec.h"
#include "qvr/runtime/chrome_trace.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/session.h"
#include "qvr/scene/scene_loader.h"

namespace qvr::cli {

namespace {

using namespace qvr::runtime;

// Frames kept in memory for trace.json: the newest ~45 s at 90 Hz.
constexpr size_t kClientFramesKept = 4096;

// Set by SIGINT/SIGTERM: the headset ends at the next frame boundary and everything measured so
// far is written.
std::atomic<bool> g_client_stop{false};

void onClientSignal(int) {
    g_client_stop.store(true);
}

struct ClientCmdOptions {
    std::string connect = "127.0.0.1:7400";
    std::string key;
    std::string key_file;
    std::string scene = "builtin:room";
    std::string profile = "default";
    std::string motion = "default";
    std::string gaze = "model";
    std::string design = "qvr";
    std::string codec = "x264";
    int frames = 300;
    int core = -1;
    uint64_t seed = 1;
    std::string out = "qvr-client";
    std::string server_stamps;
    float lod_px = 1.0f;
};

// The headset's settings from the options (each checked when parsed); an error when the key
// cannot be had.
Expected<HeadsetConfig> headsetConfig(const ClientCmdOptions& o) {
    auto key = keyFromOptions(o.key, o.key_file);
    if (!key)
        return makeError(key.error());
    std::string host, why;
    uint16_t port = 0;
    if (!parseHostPort(o.connect, host, port, why))
        return makeError("--connect: " + why);
    auto design = parseDesign(o.design, DesignScope::Runtime);
    if (!design)
        return makeError("--design: " + design.error());
    auto profile = runtimeProfileByName(o.profile);
    if (!profile)
        return makeError("--profile: " + profile.error());
    HeadsetConfig hc;
    hc.design = design->design;
    hc.fixed_e1_deg = design->fixed_e1_deg;
    hc.profile = *profile;
    hc.codec.backend = o.codec;
    hc.host = host;
    hc.port = port;
    hc.key = *key;
    hc.frames = o.frames;
    hc.core = o.core;
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    hc.renderer = glRendererFactory(gl);
    hc.stop = &g_client_stop;
    hc.keep_frames = kClientFramesKept;
    return hc;
}

nlohmann::json clientSummaryJson(const ClientCmdOptions& o, const HeadsetResult& result) {
    const DesignSummary& s = result.summary;
    const HeadsetStats& st = result.stats;
    return {{"design", s.design},
            {"frames", s.frames},
            {"frames_requested", o.frames},
            // telemetry.csv's times are ns after this steady-clock (CLOCK_MONOTONIC) instant, so
            // other tools can place their own events on its timeline
            {"clock_origin_ns", result.origin_ns},
            {"interrupted", g_client_stop.load()},
            {"fps_mean", s.fps_mean},
            {"mtp_ms_mean", s.mtp_ms_mean},
            {"mtp_ms_p99", s.mtp_ms_p99},
            {"bytes_per_frame_mean", s.bytes_per_frame_mean},
            {"e1_deg_mean", s.e1_deg_mean},
            {"frames_displayed", s.frames_displayed},
            {"frames_reused", s.frames_reused},
            {"frames_fallback_local", s.frames_fallback_local},
            {"connects", st.connects},
            {"connect_failures", st.connect_failures},
            {"server_proof_failures", st.net.server_proof_failures},
            {"incompatible_refusals", st.net.incompatible_refusals},
            {"capacity_refusals", st.net.capacity_refusals},
            {"media_drops", st.net.media_drops.total()},
            {"media_forged", st.net.media_drops[net::WireError::kBadMac]},
            {"media_replayed", st.net.media_drops[net::WireError::kReplayed]},
            {"control_drops", st.net.control_drops.total()},
            {"control_forged", st.net.control_forged},
            {"control_replayed", st.net.control_replayed},
            {"key_frame_requests", st.key_frame_requests},
            {"nacks_sent", st.net.assembler.nacks},
            {"packets_nacked", st.net.assembler.packets_nacked},
            {"packets_recovered", st.net.assembler.packets_recovered},
            {"fec_recoveries", st.net.assembler.fec_recoveries},
            {"fec_packets_recovered", st.net.assembler.fec_packets_recovered},
            {"fec_parity_received", st.net.assembler.fec_parity_received},
            {"fec_parity_unused", st.net.assembler.fec_parity_unused},
            {"streams_lost", st.streams_lost},
            {"late_frames", st.late_frames},
            {"keepalives_sent", st.net.keepalives_sent},
            {"silent_server_frames", st.silent_server_frames}};
}

// trace.json: the headset's stages, and the server's from `stamps` (a server on this machine:
// qvr server --stamps-csv F); its description goes into the summary `j`.
Status writeClientTrace(const ClientCmdOptions& o, double refresh_hz, const HeadsetResult& result,
                        const std::vector<ServerFrameStamps>& stamps, nlohmann::json& j) {
    const std::filesystem::path out(o.out);
    auto trace =
        writeChromeTrace((out / "trace.json").string(),
                         {{o.design, result.origin_ns, refresh_hz, &result.frames}}, stamps);
    if (!trace)
        return makeError(trace.error());
    j["trace"] = {{"path", "trace.json"},
                  {"frames", result.frames.size()},
                  {"first_frame", result.frames.empty() ? 0 : result.frames.front().frame},
                  {"events", trace->events},
                  {"server_frames", trace->server_frames_matched},
                  {"server_offset_ms", trace->offset.offset_ns * 1e-6},
                  {"server_offset_bound_ms", trace->offset.bound_ns * 1e-6}};
    return {};
}

void printClientReport(const HeadsetResult& result) {
    const DesignSummary& s = result.summary;
    const HeadsetStats& st = result.stats;
    fmt::print(
        "qvr client: {} fps {:.1f}, MTP {:.1f} ms (p99 {:.1f}), {:.0f} B/frame, e1 {:.1f} deg, "
        "{} displayed, {} reused, {} local fallback; {} connects, {} failed\n",
        s.design, s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean, s.e1_deg_mean,
        s.frames_displayed, s.frames_reused, s.frames_fallback_local, st.connects,
        st.connect_failures);
    if (st.connects == 0 && st.net.server_proof_failures > 0)
        std::fprintf(stderr, "qvr client: the server did not prove the pre-shared key\n");
    if (st.net.control_forged + st.net.control_replayed > 0)
        std::fprintf(stderr,
                     "qvr client: %llu forged and %llu replayed control messages ended "
                     "connections\n",
                     static_cast<unsigned long long>(st.net.control_forged),
                     static_cast<unsigned long long>(st.net.control_replayed));
}

// Runs the session, each frame's telemetry row written to `telemetry` as the frame finishes
// (only the newest frames stay in memory, for trace.json), so a session of any length runs in
// flat memory.
Expected<HeadsetResult> runSession(const ClientCmdOptions& o, HeadsetConfig& hc,
                                   const HeadsetInputs& inputs, std::ofstream& telemetry) {
    telemetry << telemetryCsvHeader();
    hc.frame_sink = [&telemetry, &o](const FrameTelemetry& t) {
        telemetry << telemetryCsvRow(o.design, t);
    };
    g_client_stop.store(false);
    std::signal(SIGINT, onClientSignal);
    std::signal(SIGTERM, onClientSignal);
    auto result = runHeadset(hc, inputs.scene, inputs.bvh, inputs.traces);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (result) {
        telemetry.close();
        if (!telemetry)
            return makeError("error writing '" +
                             (std::filesystem::path(o.out) / "telemetry.csv").string() + "'");
    }
    return result;
}

int runClient(const ClientCmdOptions& o) {
    auto hc = headsetConfig(o);
    if (!hc) {
        std::fprintf(stderr, "qvr client: %s\n", hc.error().c_str());
        return 2;
    }
    if (std::string why; !makeOutputDir(o.out, why)) {
        std::fprintf(stderr, "qvr client: --out: %s\n", why.c_str());
        return 2;
    }
    auto inputs =
        loadHeadsetInputs(o.scene, o.motion, o.gaze, hc->profile.refresh_hz, o.frames, o.seed);
    if (!inputs) {
        std::fprintf(stderr, "qvr client: %s\n", inputs.error().c_str());
        return 2;
    }
    const std::string telemetry_path = (std::filesystem::path(o.out) / "telemetry.csv").string();
    std::ofstream telemetry(telemetry_path);
    if (!telemetry) {
        std::fprintf(stderr, "qvr client: cannot write '%s'\n", telemetry_path.c_str());
        return 2;
    }
    auto result = runSession(o, *hc, *inputs, telemetry);
    if (!result) {
        std::fprintf(stderr, "qvr client: %s\n", result.error().c_str());
        return 1;
    }
    nlohmann::json j = clientSummaryJson(o, *result);
    // The server's stamps are read after the session (the server has stopped or flushed); a
    // file that went bad meanwhile costs the server's rows on the timeline, not the session.
    std::vector<ServerFrameStamps> stamps;
    bool stamps_bad = false;
    if (!o.server_stamps.empty()) {
        auto read = readServerStamps(o.server_stamps);
        if (read)
            stamps = std::move(*read);
        else
            std::fprintf(stderr, "qvr client: --server-stamps: %s\n", read.error().c_str());
        stamps_bad = !read;
    }
    if (Status st = writeClientTrace(o, hc->profile.refresh_hz, *result, stamps, j); !st) {
        std::fprintf(stderr, "qvr client: %s\n", st.error().c_str());
        return 1;
    }
    std::ofstream(std::filesystem::path(o.out) / "summary.json") << j.dump(2) << "\n";
    printClientReport(*result);
    if (g_client_stop.load()) {
        std::fprintf(stderr, "qvr client: interrupted: kept %zu of %d frames in %s\n",
                     result->frames.size(), o.frames, o.out.c_str());
        return 130;
    }
    return stamps_bad ? 2 : 0;
}

// --server-stamps: a readable file that, once it has a first line, starts with the stamps
// header (the server writes the file while this client runs, so it may still be empty).
std::string serverStampsError(std::string& path) {
    if (std::string why = readableFile()(path); !why.empty())
        return why;
    std::ifstream in(path);
    std::string line;
    if (std::getline(in, line) && !in.eof() && line + "\n" != kServerStampsHeader)
        return "'" + path + "' is not a server stamps file (qvr server --stamps-csv): its header";
    return {};
}

}  // namespace

static Registered registerClient(CLI::App& app) {
    auto o = std::make_shared<ClientCmdOptions>();
    CLI::App* cmd =
        app.add_subcommand("client", "The headset: fovea local, periphery from a server");
    cmd->add_option("--connect", o->connect, "Server HOST:PORT")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                std::string host, why;
                uint16_t port = 0;
                return parseHostPort(text, host, port, why) ? std::string() : why;
            },
            "HOST:PORT", "HOST_PORT"))
        ->capture_default_str();
    addKeyOptions(cmd, o->key, o->key_file);
    cmd->add_option("--scene", o->scene, "Scene")->capture_default_str();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime);
    cmd->add_option("--motion", o->motion, "Head motion: default, a .bvh, a pose CSV, still")
        ->capture_default_str();
    addGazeSourceOption(cmd, o->gaze);
    cmd->add_option("--design", o->design, "local, remote, ffr, fixed:E, sw or qvr")
        ->check(CLI::Validator(
            [](std::string& name) -> std::string {
                auto d = parseDesign(name, DesignScope::Runtime);
                return d ? std::string() : d.error();
            },
            "DESIGN", "DESIGN"))
        ->capture_default_str();
    addCodecOption(cmd, o->codec);
    addFramesOption(cmd, o->frames, 1, 1'000'000, "Frames to run");
    addLodOption(cmd, o->lod_px);
    addCoreOption(cmd, o->core, "Pin the headset loop to this core (-1: no)");
    addSeedOption(cmd, o->seed, "Gaze model seed");
    cmd->add_option("--server-stamps", o->server_stamps,
                    "The server's --stamps-csv file: its stages go on trace.json's timeline")
        ->check(CLI::Validator(serverStampsError, "FILE", "SERVER_STAMPS"));
    cmd->add_option("--out", o->out, "Output folder (telemetry.csv, summary.json, trace.json)")
        ->check(outputFolder())
        ->capture_default_str();
    return {cmd, [o] { return runClient(*o); }};
}

QVR_REGISTER_COMMAND(90, registerClient);

}  // namespace qvr::cli
