// Head-pose traces (paper §5: the motion that drives each frame's pose and LIWC's motion code):
// timestamped poses, interpolation, placement in a level, and the CSV format both ways.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/pose.h"

namespace qvr {

struct PoseSample {
    double t_ms = 0.0;
    Pose pose;
};

struct PoseTrace {
    std::vector<PoseSample> samples;  // strictly increasing t_ms
};

// The pose at time t_ms: position interpolated linearly, orientation by slerp; clamped to the
// first and last samples outside the trace. The trace must not be empty.
Pose poseAt(const PoseTrace& trace, double t_ms);

// Samples the trace at rate_hz from its first timestamp (source times t0 + k·1000/rate_hz; the
// output's t_ms start at 0). Fails if the trace is shorter than the frames asked for
// (frames = 0: as many as fit).
Expected<PoseTrace> resamplePoses(const PoseTrace& trace, double rate_hz, int frames);

// Gaussian smoothing in time (sigma in ms) of positions and orientations: removes mocap jitter.
PoseTrace smoothPoses(const PoseTrace& trace, double sigma_ms);

// Moves the trace so its first pose stands at origin_m (horizontally; heights are kept relative
// to origin_m.y) and looks along yaw_deg (about +y, 0 = −z): a level's spawn point.
PoseTrace placePoses(const PoseTrace& trace, const glm::vec3& origin_m, double yaw_deg);

// CSV: header line "t_ms,qw,qx,qy,qz,x,y,z", then one pose per line; orientation as a unit
// quaternion in the y-up, −z-forward frame of qvr/core/pose.h, position in metres.
std::string poseTraceToCsv(const PoseTrace& trace);
Status writePoseCsv(const PoseTrace& trace, const std::string& path);
// Strict: exact header, 8 finite fields per line, increasing times, unit quaternions (within
// 1e-3; renormalised), bounded size. Errors name the line.
Expected<PoseTrace> parsePoseCsv(std::string_view text, std::string_view source_name = "csv");
Expected<PoseTrace> loadPoseCsv(const std::string& path);

}  // namespace qvr
