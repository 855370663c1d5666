// `qvr trace record`: renders a level along a head-motion and gaze trace and writes the measured
// workload trace (paper §5; docs/RECORDING.md). Interruptible: Ctrl-C finishes the current frame
// and keeps every whole line written so far.
#include <unistd.h>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "bench_commands.h"
#include "cli_parse.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/trace/record_report.h"

namespace qvr::cli {

namespace {

constexpr const char* kCmd = "qvr trace record";

// Set by SIGINT/SIGTERM; the recorder checks it between frames.
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void onStopSignal(int) {
    g_stop.store(true);
}

struct RecordCliOptions {
    RecordOptions record;
    std::string profile = "default";
    std::string out;
    bool quiet = false;
};

Registered registerTraceRecord(CLI::App& parent) {
    auto o = std::make_shared<RecordCliOptions>();
    CLI::App* cmd = parent.add_subcommand(
        "record",
        "Render a level along motion and gaze traces and write the measured workload "
        "trace (docs/RECORDING.md)");
    cmd->add_option("--scene", o->record.scene, kSceneHelp)->required();
    cmd->add_option("--motion", o->record.motion,
                    "Head motion: pose CSV, BVH file, or 'default' (CMU 01_01 from "
                    "assimp-testmodels)")
        ->capture_default_str();
    auto* gaze = cmd->add_option("--gaze", o->record.gaze_csv, "Gaze CSV (t_ms,x_deg,y_deg)")
                     ->check(readableFile());
    auto* seed = addSeedOption(cmd, o->record.gaze_seed, "Seed of the gaze model", "--gaze-seed");
    gaze->excludes(seed);
    seed->excludes(gaze);
    addProfileOption(cmd, o->profile);
    addFramesOption(cmd, o->record.frames, 1, 1'000'000, "Frames to record at the display rate");
    addInt(cmd, "--spawn", o->record.spawn, "Spawn point to start from", 0, 1'000'000);
    cmd->add_option("--name", o->record.name, "Trace name (default: the scene name)");
    addInt(cmd, "--raster-scale", o->record.raster_scale,
           "CPU z-buffer (overdraw, depth, objects) at 1/N resolution", 1, 16);
    addInt(cmd, "--foreground", o->record.foreground_objects,
           "Foreground objects for a scene that marks no interactive objects (a model file): the "
           "nearest visible ones",
           0, 1000);
    addOutputFileOption(cmd, o->out, "Output workload trace (JSON lines)");
    cmd->add_flag("--quiet", o->quiet, "No progress line");
    Action action = [o]() -> int {
        o->record.profile = checkedHmdProfile(o->profile);
        auto inputs = prepareRecording(o->record);
        if (!inputs) {
            std::fprintf(stderr, "%s: %s\n", kCmd, inputs.error().c_str());
            return 2;
        }
        auto renderer = GlRenderer::create();
        if (!renderer) {
            std::fprintf(stderr, "%s: renderer: %s\n", kCmd, renderer.error().c_str());
            return 1;
        }
        std::ofstream out(o->out, std::ios::binary | std::ios::trunc);
        if (!out) {
            std::fprintf(stderr, "%s: cannot write '%s'\n", kCmd, o->out.c_str());
            return 1;
        }
        const bool tty = isatty(STDERR_FILENO) != 0;
        const std::string line =
            recordingHeadline(o->record, *inputs, (*renderer)->info().renderer);
        std::fprintf(stderr, "%s: %s", kCmd, line.c_str());
        auto progress = [o, tty](const RecordProgress& p) {
            if (!o->quiet)
                std::fputs(recordProgressLine(p, tty).c_str(), stderr);
        };
        g_stop.store(false);
        std::signal(SIGINT, onStopSignal);
        std::signal(SIGTERM, onStopSignal);
        auto result = recordWorkload(o->record, *inputs, **renderer, out, &g_stop, progress);
        std::signal(SIGINT, SIG_DFL);
        std::signal(SIGTERM, SIG_DFL);
        out.close();
        if (tty && !o->quiet)
            std::fputc('\n', stderr);
        if (!result) {
            std::fprintf(stderr, "%s: %s (the lines written before stay valid)\n", kCmd,
                         result.error().c_str());
            return 1;
        }
        if (result->stopped) {
            std::fprintf(stderr, "%s: interrupted: kept %lld of %d frames in %s\n", kCmd,
                         static_cast<long long>(result->frames_written), o->record.frames,
                         o->out.c_str());
            return 130;
        }
        std::fputs(recordingDoneLine(*result, o->out).c_str(), stdout);
        return 0;
    };
    return {cmd, action};
}

}  // namespace

QVR_REGISTER_SUBCOMMAND("trace", 30, registerTraceRecord);

}  // namespace qvr::cli
