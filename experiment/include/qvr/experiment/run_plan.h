// The plan of `qvr run`: what it runs (scene, traces, link, display, designs, frames), how
// (pinning, frames in flight, wait limit, level of detail), what it records (video, quality
// samples) and which calibration predicts it; and the choice of that calibration.
#pragma once

#include <cstdint>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/experiment/calibration.h"
#include "qvr/sim/hardware.h"

namespace qvr::experiment {

struct RunOptions {
    std::string scene = "builtin:room";
    std::string motion = "default";
    std::string gaze = "model";
    std::string net = "wifi";
    std::string profile = "default";
    std::string designs = "local,remote,ffr,fixed:10,fixed:20,sw,qvr";
    std::string out = "qvr-run";
    std::string codec = "x264";
    int frames = 150;
    uint64_t seed = 1;
    double remote_timeout_ms = 250.0;
    bool video = true;
    bool fovea_border = true;
    bool quiet = false;
    int video_max_frames = 900;
    int quality_every = 15;  // every Nth displayed frame is measured against a full render
    bool one_pass_periphery = false;
    bool no_holes = false;
    std::string share_periphery = "off";  // the server's --share-periphery
    double headset_share = 1.0;
    std::string ring_counts = "clusters";
    int pipeline_depth = 2;
    int warmup_frames = 10;  // each design's first frames: start-up, outside the statistics
    float lod_px = 1.0f;
    std::string hardware;      // a calibration (qvr calibrate --out); none: cached or measured
    bool recalibrate = false;  // measure even when a cached calibration exists
    // Headsets on the one server (headsets.h): headset 0 in this process as always, the others
    // each in a process of its own, all started together for every design.
    int headsets = 1;
    bool identical_workloads = false;  // every headset the plan's motion, gaze and seed
    double headset_offset_ms = 0.0;    // headset k plays k × this ahead (close, distinct paths)
    std::string command_line;
};

// What `qvr run` calibrates (and probes the machine's speed) with: the run's scene, profile,
// codec and level of detail, on the headset's core.
CalibrateOptions runCalibrateOptions(const RunOptions& plan);

// The calibration the prediction uses: the file given, this machine's cached one, or a fresh
// measurement (written to the cache). Always measured before the run: no constant is fitted to
// the run it predicts.
struct CalibrationChoice {
    HardwareConfig hardware;
    std::string source;  // "file", "cached" or "measured"
    std::string path;
    double seconds = 0.0;
    std::string note;  // one sentence for the console and the report
};

Expected<CalibrationChoice> chooseCalibration(const RunOptions& plan);

}  // namespace qvr::experiment
