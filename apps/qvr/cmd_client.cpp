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

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/session_outputs.h"
#include "qvr/runtime/session_settings.h"
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
    HeadsetSettings settings;
    std::string connect = "127.0.0.1:7400";
    std::string scene = "builtin:room";
    std::string motion = "default";
    std::string gaze = "model";
    uint64_t seed = 1;
    std::string out = "qvr-client";
    std::string server_stamps;
};

// The headset's settings from the options (each checked when parsed); an error when the key
// cannot be had.
Expected<HeadsetConfig> clientConfig(ClientCmdOptions o) {
    std::string why;
    if (!parseHostPort(o.connect, o.settings.host, o.settings.port, why))
        return makeError("--connect: " + why);
    auto hc = headsetConfig(o.settings);
    if (hc) {
        hc->stop = &g_client_stop;
        hc->keep_frames = kClientFramesKept;
    }
    return hc;
}

// Runs the session with telemetry.csv written as frames finish; SIGINT/SIGTERM end it at the
// next frame boundary and keep what was measured.
Expected<HeadsetResult> runSession(HeadsetConfig& hc, const HeadsetInputs& inputs,
                                   const std::string& telemetry_path, std::ofstream& telemetry) {
    g_client_stop.store(false);
    std::signal(SIGINT, onClientSignal);
    std::signal(SIGTERM, onClientSignal);
    auto result = runHeadset(hc, inputs.scene, inputs.bvh, inputs.traces);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (result)
        if (Status st = finishTelemetryCsv(telemetry_path, telemetry); !st)
            return makeError(st.error());
    return result;
}

int runClient(const ClientCmdOptions& o) {
    auto hc = clientConfig(o);
    if (!hc)
        return fail("client", hc.error(), 2);
    if (std::string why; !makeOutputDir(o.out, why))
        return fail("client", "--out: " + why, 2);
    auto inputs = loadHeadsetInputs(o.scene, o.motion, o.gaze, hc->profile.refresh_hz,
                                    o.settings.frames, o.seed);
    if (!inputs)
        return fail("client", inputs.error(), 2);
    const std::string telemetry_path = (std::filesystem::path(o.out) / "telemetry.csv").string();
    std::ofstream telemetry;
    if (Status st = startTelemetryCsv(telemetry_path, o.settings.design, telemetry, *hc); !st)
        return fail("client", st.error(), 2);
    auto result = runSession(*hc, *inputs, telemetry_path, telemetry);
    if (!result)
        return fail("client", result.error(), 1);
    const ServerStampsRead stamps = readServerStampsAfterSession(o.server_stamps);
    if (!stamps.error.empty())
        std::fprintf(stderr, "qvr client: --server-stamps: %s\n", stamps.error.c_str());
    const ClientSession session{o.settings.design, o.settings.frames, g_client_stop.load(),
                                hc->profile.refresh_hz};
    if (Status st = writeClientOutputs(o.out, session, *result, stamps.stamps); !st)
        return fail("client", st.error(), 1);
    fmt::print("{}", clientReportLine(*result));
    for (const std::string& warning : clientWarnings(result->stats))
        std::fprintf(stderr, "qvr client: %s\n", warning.c_str());
    if (g_client_stop.load()) {
        std::fprintf(stderr, "qvr client: interrupted: kept %zu of %d frames in %s\n",
                     result->frames.size(), o.settings.frames, o.out.c_str());
        return 130;
    }
    return stamps.error.empty() ? 0 : 2;
}

// --server-stamps: a readable file that, once it has a first line, starts with the stamps
// header (the server writes the file while this client runs, so it may still be empty).
std::string serverStampsError(std::string& path) {
    std::string why = readableFile()(path);
    return why.empty() ? serverStampsHeaderError(path) : why;
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
    addKeyOptions(cmd, o->settings.key, o->settings.key_file);
    cmd->add_option("--scene", o->scene, "Scene")->capture_default_str();
    addProfileOption(cmd, o->settings.profile, ProfileNames::kRuntime);
    addMotionOption(cmd, o->motion);
    addGazeSourceOption(cmd, o->gaze);
    cmd->add_option("--design", o->settings.design, "local, remote, ffr, fixed:E, sw or qvr")
        ->check(explainedBy(
            [](const std::string& name) { return parseDesign(name, DesignScope::Runtime); },
            "DESIGN", "DESIGN"))
        ->capture_default_str();
    addCodecOption(cmd, o->settings.codec);
    addFramesOption(cmd, o->settings.frames, 1, 1'000'000, "Frames to run");
    addLodOption(cmd, o->settings.lod_px);
    addCoreOption(cmd, o->settings.core, "Pin the headset loop to this core (-1: no)");
    addSeedOption(cmd, o->seed, "Gaze model seed");
    cmd->add_option("--server-stamps", o->server_stamps,
                    "The server's --stamps-csv file: its stages go on trace.json's timeline")
        ->check(CLI::Validator(serverStampsError, "FILE", "SERVER_STAMPS"));
    addOutputFolderOption(cmd, o->out, "Output folder (telemetry.csv, summary.json, trace.json)");
    return {cmd, [o] { return runClient(*o); }};
}

QVR_REGISTER_COMMAND(90, registerClient);

}  // namespace qvr::cli
