// `qvr run`: a render server and a headset client on loopback, each pinned to its own core, run
// every design of the runtime over the same frames through net's link emulator (paper Fig. 4,
// §6.1 measured for real), then write summary.json, per-frame telemetry, report.html with
// gnuplot figures, the video the headset displayed for `qvr`, and `qvr sim`'s prediction for the
// workload recorded during the run. The experiment is the experiment part's (run_experiment.h
// runExperiment); this file parses and checks the options.
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/codec/video_codec.h"
#include "qvr/core/design.h"
#include "qvr/experiment/run_experiment.h"
#include "qvr/experiment/run_plan.h"
#include "qvr/net/link_emulator.h"
#include "qvr/runtime/cpu_share.h"
#include "qvr/runtime/session.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

using namespace qvr::runtime;

int runRun(const RunOptions& o) {
    auto designs = parseDesignList(o.designs, DesignScope::Runtime);
    if (!designs) {
        std::fprintf(stderr, "qvr run: --designs: %s\n", designs.error().c_str());
        return 2;
    }
    if (o.warmup_frames < 0 || o.warmup_frames > o.frames - 2) {
        std::fprintf(stderr, "qvr run: --warmup-frames must be within 0..frames-2 (%d), got %d\n",
                     o.frames - 2, o.warmup_frames);
        return 2;
    }
    auto profile = runtimeProfileByName(o.profile);
    if (!profile) {
        std::fprintf(stderr, "qvr run: --profile: %s\n", profile.error().c_str());
        return 2;
    }
    if (std::string why; !makeOutputDir(o.out, why)) {
        std::fprintf(stderr, "qvr run: --out: %s\n", why.c_str());
        return 2;
    }
    return runExperiment(o, *designs, *profile);
}

}  // namespace

static Registered registerRun(CLI::App& app) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand(
        "run", "Server + headset on loopback (each on its own core): every design, measured");
    cmd->add_option("--scene", o->scene, "Scene (builtin:room, openarena:MAP, a file)")
        ->capture_default_str();
    addMotionOption(cmd, o->motion);
    addGazeSourceOption(cmd, o->gaze);
    addLinkOption(cmd, o->net);
    addFramesOption(cmd, o->frames, 2, 100000, "Frames per design");
    cmd->add_option("--designs", o->designs,
                    "Comma-separated: local, remote, ffr (= fixed:5), fixed:E for any e1 E in "
                    "degrees, sw, qvr, aimd")
        ->check(explainedBy(
            [](const std::string& list) { return parseDesignList(list, DesignScope::Runtime); },
            "DESIGNS", "DESIGNS"))
        ->capture_default_str();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime);
    addOutputFolderOption(cmd, o->out, "Output folder");
    addCodecOption(cmd, o->codec);
    addSeedOption(cmd, o->seed, "Gaze model and simulator seed");
    addFinite(cmd, "--remote-timeout-ms", o->remote_timeout_ms,
              "Remote layers later than this after the local render are late (frame reuse)", 1.0,
              10000.0);
    addPeripheryPassFlags(cmd, o->one_pass_periphery, o->no_holes);
    addSharePeripheryOption(cmd, o->share_periphery);
    addFinite(cmd, "--headset-share", o->headset_share,
              "Fraction of its core the headset process may use (CFS quota per 10 ms, cgroups; "
              "needs root): the analogue of Table 4's slower headset GPUs",
              CpuShareGroup::kMinShare + 1e-9, 1.0);
    cmd->add_option("--ring-counts", o->ring_counts,
                    "LIWC's triangle rings: clusters (what the fovea draws, cheap) or bvh "
                    "(every scene triangle, exact, the earlier input)")
        ->check(CLI::IsMember({"clusters", "bvh"}))
        ->capture_default_str();
    addLodOption(cmd, o->lod_px);
    cmd->add_option("--warmup-frames", o->warmup_frames,
                    "Each design's first frames are its session's start-up (connection, first "
                    "renders, key frames, the policy's first decisions; for a design that asks the "
                    "server for layers, also until the first of them is on screen): run and "
                    "logged, but left out of FPS, MTP, bytes and e1; their worst MTP is reported "
                    "apart")
        ->capture_default_str();
    addInt(cmd, "--pipeline", o->pipeline_depth,
           "Frames in flight on the headset: 1 (sequential) or 2 (request n+1 before finishing n)",
           1, 2);
    addHardwareOption(cmd, o->hardware,
                      "Calibration for the prediction (qvr calibrate --out FILE); without it the "
                      "cached calibration of this machine, or a fresh one measured first");
    cmd->add_flag("--recalibrate", o->recalibrate,
                  "Measure the calibration again even when a cached one exists");
    cmd->add_flag("!--no-video", o->video, "Do not record the qvr display video");
    cmd->add_flag("--quiet", o->quiet, "No progress line on a terminal");
    addInt(cmd, "--headsets", o->headsets,
           "Headsets on the one server, each design run with all at once (each its own motion "
           "recording and gaze seed; the others in processes of their own)",
           kMinHeadsets, kMaxHeadsets);
    cmd->add_flag("--identical-workloads", o->identical_workloads,
                  "Every headset the same motion and gaze (--motion, --gaze, --seed)");
    addFinite(cmd, "--headset-offset-ms", o->headset_offset_ms,
              "Headset k plays its motion and gaze k times this far ahead: with "
              "--identical-workloads, headsets on one path a fraction of a frame apart, whose "
              "poses are close and never the same",
              0.0, 1000.0);
    addInt(cmd, "--quality-every", o->quality_every,
           "Measure every Nth displayed frame against a full-resolution render after each "
           "design's run (0: off)",
           0, 100000);
    cmd->add_flag("!--no-fovea-border", o->fovea_border,
                  "Do not draw the e1 circle (the fovea layer's edge) in the video");
    return {
        cmd, [o] {
            o->command_line = fmt::format(
                "qvr run --scene {} --motion {} --gaze {} --net {} --frames {} --designs {} "
                "--profile {} --codec {} --seed {} --lod-px {} --pipeline {} --headset-share {} "
                "--ring-counts {}{}{}{}{}",
                o->scene, o->motion, o->gaze, o->net, o->frames, o->designs, o->profile, o->codec,
                o->seed, o->lod_px, o->pipeline_depth, o->headset_share, o->ring_counts,
                o->one_pass_periphery ? " --one-pass-periphery" : "",
                o->no_holes ? " --no-holes" : "",
                o->share_periphery != "off" ? " --share-periphery " + o->share_periphery : "",
                o->headsets > 1
                    ? fmt::format(" --headsets {}{}{}", o->headsets,
                                  o->identical_workloads ? " --identical-workloads" : "",
                                  o->headset_offset_ms > 0.0
                                      ? fmt::format(" --headset-offset-ms {}", o->headset_offset_ms)
                                      : "")
                    : "");
            return runRun(*o);
        }};
}

QVR_REGISTER_COMMAND(90, registerRun);

static Registered registerRunHeadset(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand(
        "run-headset", "qvr run --headsets' other headsets (internal: settings on stdin)");
    cmd->group("");  // not listed: qvr run starts it
    return {cmd, [] { return runHeadsetChild(); }};
}
QVR_REGISTER_COMMAND(93, registerRunHeadset);

}  // namespace qvr::cli
