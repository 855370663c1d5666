// What `qvr trace motion` and `qvr trace gaze` say about a trace they made: the head's turning
// speed, the gaze model's events, and the lines reporting them.
#pragma once

#include <cstdint>
#include <string>

#include "qvr/trace/bvh.h"
#include "qvr/trace/gaze_model.h"
#include "qvr/trace/head_motion.h"
#include "qvr/trace/pose_trace.h"

namespace qvr {

struct HeadTurnStats {
    double mean_deg_s = 0.0;  // over every step between consecutive poses
    double max_deg_s = 0.0;
};

// The head's turning speed between consecutive poses of a trace sampled at `rate_hz`.
HeadTurnStats headTurnStats(const PoseTrace& trace, double rate_hz);

// The recording a head trace came from (frames, rate, joints, length unit, head joint) and the
// trace written from it (poses, length, turning speed), as two lines.
std::string headTraceReport(const std::string& bvh_path, const BvhMotion& motion,
                            const HeadMotionOptions& options, const PoseTrace& trace,
                            const std::string& out_path);

struct GazeEventCounts {
    int fixations = 0;
    int pursuits = 0;
    int saccades = 0;
    double mean_saccade_deg = 0.0;  // mean amplitude; 0 without saccades
};

// The gaze model's events in a generated trace, by kind.
GazeEventCounts countGazeEvents(const GazeTrace& trace);

// A generated gaze trace as one line: samples, rate, length, seed and its events.
std::string gazeTraceReport(const GazeTrace& trace, const GazeModelConfig& model, uint64_t seed,
                            const std::string& out_path);

}  // namespace qvr
