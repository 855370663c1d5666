// The workload recorder (paper §5): renders a level frame by frame along a head-motion trace and
// a gaze trace and writes what each frame costs in the workload format
// (docs/WORKLOAD_FORMAT.md): triangles and shaded pixels per eccentricity ring, the periphery's
// real x264 bytes at each layer scale, and the static design's split (§6.1).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "qvr/codec/video_codec.h"
#include "qvr/core/expected.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/trace/gaze_model.h"
#include "qvr/trace/pose_trace.h"
#include "qvr/workload/workload.h"

namespace qvr {

class Renderer;

struct RecordOptions {
    std::string name;   // the trace's name (e.g. "oa-dm5-h"); empty: derived from the scene
    std::string scene;  // a loadScene name
    std::string motion = "default";  // pose CSV, BVH file, or "default" (defaultBvhPath())
    std::string gaze_csv;            // empty: the seeded gaze model
    uint64_t gaze_seed = 1;
    HmdProfile profile;
    int frames = 300;
    int spawn = 0;
    double ring_deg = 1.0;
    int rings = 100;
    // Layer scales bits per pixel are measured at: powers of two, each its own x264 stream per
    // eye, made by box-halving the full-resolution frame.
    std::vector<double> scales = {1, 2, 4, 8, 16, 32};
    // The CPU raster (overdraw, depth, object coverage) runs at 1/raster_scale resolution.
    int raster_scale = 2;
    double object_cell_m = 1.0;  // objects = batches split by cells of this size
    // The static design's foreground (§2, Table 1): every visible object of the scene's
    // interactive batches (a level's items, the room's chess pieces); a scene that marks none
    // (a model file) takes this many nearest visible non-flat objects instead.
    int foreground_objects = 1;
    double flat_object_m = 0.1;  // objects thinner than this on some axis are architecture
    CodecConfig codec;
    // The paper's codec setting (§2.3: "streamed with lossless H.264"), measured beside `codec`
    // as its own persistent streams per eye and scale: `codec` with CRF 0, which x264 codes
    // losslessly (of the 4:2:0 image it is given). Off: the trace has no bpp_lossless.
    bool record_lossless = true;
    // Levels are loaded with their items, the interactive objects the static design renders.
    SceneLoadOptions scene_options = [] {
        SceneLoadOptions o;
        o.load_items = true;
        return o;
    }();
};

struct RecordProgress {
    int64_t frame = 0;  // frames written so far
    int64_t frames = 0;
    double elapsed_s = 0.0;
    double last_frame_s = 0.0;
};

struct RecordResult {
    int64_t frames_written = 0;
    bool stopped = false;  // the stop flag ended the recording early
    double elapsed_s = 0.0;
    WorkloadHeader header;
};

// Everything a recording needs that can fail before rendering starts: the scene, the spawn
// point, motion and gaze placed and resampled to the display rate. Errors name the input.
struct RecordInputs {
    Scene scene;
    SceneLoadReport report;
    PoseTrace poses;  // one per frame at the display rate, placed at the spawn point
    GazeTrace gaze;
    std::string motion_source;
    std::string gaze_source;
};
Expected<RecordInputs> prepareRecording(const RecordOptions& options);

// Records into `out` (header first, then one flushed line per frame). Checks `stop` before each
// frame, so an interrupt leaves whole lines only. `renderer` must have nothing uploaded yet
// (the scene is uploaded here); the GL renderer in practice, the null one in tests that need no
// pixels. Runtime failures (GL, codec, write) are errors; the lines written so far stay valid.
Expected<RecordResult> recordWorkload(
    const RecordOptions& options, const RecordInputs& inputs, Renderer& renderer, std::ostream& out,
    const std::atomic<bool>* stop = nullptr,
    const std::function<void(const RecordProgress&)>& progress = {});

}  // namespace qvr
