// The per-frame workload description every fovea-sizing policy and the simulator read (paper
// §4.1, §5): what a frame costs locally as a function of e1 and what its periphery costs in
// bytes as a function of the layer plan. Recorded from real levels (trace part) or generated
// (synthetic.h); stored in the JSON-lines format documented in docs/WORKLOAD_FORMAT.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

// Limits a trace must respect; the reader rejects anything larger (untrusted input).
inline constexpr int kMaxRings = 512;
inline constexpr int kMaxScales = 32;
inline constexpr int64_t kMaxTraceFrames = 10'000'000;

// The static collaborative design's split of one frame (paper §2.2, §6.1): the draw batches
// nearest the viewer rendered locally, the background plus its depth fetched from the server.
struct StaticSplit {
    double fg_triangles = 0.0;        // both eyes
    double fg_screen_fraction = 0.0;  // share of the full frame's pixels the foreground covers
    double bg_bytes = 0.0;            // encoded background, both eyes, full resolution
    double depth_bytes = 0.0;         // encoded depth the composition needs, both eyes
    // The background in the paper's codec setting (lossless H.264, §2.3); < 0: not recorded.
    double bg_bytes_lossless = -1.0;
};

struct WorkloadFrame {
    int64_t index = 0;
    double time_ms = 0.0;
    Pose head;
    Gaze gaze;
    // Both eyes together, ring k covering eccentricities [k·ring_deg, (k+1)·ring_deg) from the
    // gaze. Triangles are those whose screen footprint lies in the ring (after culling);
    // pixels are full-resolution shaded pixels (including overdraw for recorded traces).
    std::vector<double> triangles_per_ring;
    std::vector<double> pixels_per_ring;
    // Encoded bits per layer pixel of the periphery at each of the header's scales.
    std::vector<double> bits_per_pixel;
    // The same in the paper's codec setting (lossless H.264, §2.3: "streamed with lossless
    // H.264"); empty when the trace did not record it (docs/RECORDING.md).
    std::vector<double> bits_per_pixel_lossless;
    StaticSplit static_split;
    // The fragments the headset's fovea pass shaded per fovea pixel, both eyes (its overdraw,
    // RenderStats::fragment_invocations); < 0 where not recorded (a qvr run's workload.jsonl
    // records it; docs/WORKLOAD_FORMAT.md).
    double fovea_fragments_per_px = -1.0;
};

struct WorkloadHeader {
    std::string name;
    std::string source;  // "synthetic seed=…", "recorded openarena:oa_dm5 …", free text
    HmdProfile profile;
    double ring_deg = 1.0;
    int rings = 0;
    std::vector<double> scales;  // strictly increasing, first ≥ 1
    int batches = 0;             // draw batches per frame (Table 3), 0 if unknown
};

struct WorkloadTrace {
    WorkloadHeader header;
    std::vector<WorkloadFrame> frames;
};

// Sums over rings, with the ring that e splits counted in proportion to its covered width.
double sumWithinDeg(const std::vector<double>& per_ring, double ring_deg, double e_deg);
double sumTotal(const std::vector<double>& per_ring);

// What a frame shows, as a 32-bit key (never 0) of its head pose rounded to 0.1 mm and 1e-5 of
// a quaternion component: the calibration's bits frame by frame (RuntimeCosts::bits_frame_key)
// apply to a run's frame only where the keys agree. Not the gaze: the periphery's two layers
// together cover the whole view wherever the eye looks, and the calibration's gaze (seed 7) is
// not a run's (seed 1).
uint32_t frameContentKey(const Pose& head);
// Frame i's time in its head motion and gaze, the one formula the headset, `qvr run`'s prediction
// and the calibration all use, so their poses agree to the bit (and with them the keys above).
inline double contentTimeMs(int64_t frame, double refresh_hz) {
    return 1000.0 * static_cast<double>(frame) / refresh_hz;
}

// Bits per pixel at scale s, interpolated log-log between the header's scales and held
// constant beyond either end.
double bitsPerPixelAt(const WorkloadHeader& header, const WorkloadFrame& frame, double scale);

// Bytes the server sends for this plan: middle and outer layers of both eyes.
struct PeripheryBytes {
    double middle = 0.0;
    double outer = 0.0;
    double total() const { return middle + outer; }
};
PeripheryBytes peripheryBytes(const WorkloadHeader& header, const WorkloadFrame& frame,
                              const LayerPlan& plan);

// Which recorded codec setting periphery and background bytes come from (docs/MODEL.md):
// `stream` = our low-latency x264 setting (CRF 23), `lossless` = the paper's (§2.3).
enum class CodecModel { kStream, kLossless };
Expected<CodecModel> parseCodecModel(const std::string& name);
const char* codecModelName(CodecModel model);
// True when every frame carries the lossless measurements.
bool hasLosslessCodec(const WorkloadTrace& trace);
// Puts the chosen setting's measurements into bits_per_pixel and static_split.bg_bytes (the
// fields every consumer reads). kLossless on a trace without them is an error naming the trace.
Status applyCodecModel(WorkloadTrace& trace, CodecModel model);

// Checks the invariants the reader enforces (sizes, finiteness, signs, monotonic time); used
// by the generator and the recorder before they write.
Status validateTrace(const WorkloadTrace& trace);
Status validateHeader(const WorkloadHeader& header);
// One frame against its header; previous_time_ms is the previous frame's time (−∞ for the
// first). The reader calls this per line so that errors name the line.
Status validateFrame(const WorkloadHeader& header, const WorkloadFrame& frame,
                     double previous_time_ms);

}  // namespace qvr
