// `qvr calibrate`: this machine's costs of the runtime's parts, measured by micro-benchmarks that
// run none of `qvr run`'s pipeline — each part alone, on the headset's core, over a spread of
// sizes — and fitted to the runtime pipeline model's linear costs (sim/hardware.h RuntimeCosts).
// Shared by `qvr calibrate` and `qvr run` (which calibrates first when given no file).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/sim/hardware.h"

namespace qvr::experiment {

struct CalibrateOptions {
    std::string scene = "builtin:room";
    std::string profile = "default";
    std::string codec = "x264";
    float lod_px = 1.0f;
    int core = 0;        // pinned like the headset (-1: unpinned)
    bool quick = false;  // fewer samples (qvr run's pass before a run)
    bool verbose = true;
};

// One fitted part: its cost, the samples it was fitted on and how far they scatter around it.
struct CalibratedPart {
    std::string name;
    std::string what;  // what one sample is
    int samples = 0;
    PartCost cost;
    double median_ms = 0.0, min_ms = 0.0, max_ms = 0.0;    // of the samples
    double residual_rms_pct = 0.0;                         // RMS of (measured − fit) / measured
    std::vector<std::array<double, 3>> samples_ms_px_tri;  // every sample, in the JSON
    std::vector<int> samples_full_frame;                   // 1 where that sample is a whole frame
    std::vector<double> samples_fragments;  // its shaded fragments (−1: not counted)
};

// The e1 of the frames the co-running measurement and the speed probe time: where qvr and sw
// settle on the reference scenes.
inline constexpr double kCoRunE1Deg = 10.0;

// One speed probe (SpeedProbe below).
struct SpeedSample {
    double headset_ms = 0.0;  // median of kFrames headset frames
    double server_ms = 0.0;   // median of kFrames server frames
};

struct Calibration {
    RuntimeCosts costs;
    std::vector<CalibratedPart> parts;
    std::string machine;
    std::string date;
    std::string command;
    double seconds = 0.0;
    double load_avg_before = 0.0;
    int bits_samples = 0;  // P-frames the bits-per-pixel law was fitted on
    // Each law's b over the log fit's: how far the mean P-frame sits above the geometric mean.
    std::array<double, 2> bits_mean_over_geometric{1.0, 1.0};
    int padding_samples = 0;          // P-frame pairs the padding ratio was fitted on
    int bits_full_frame_samples = 0;  // whole-frame P-frames (remote's layer) measured
    nlohmann::json codec_by_e1;       // per calibration e1: median P-frame bits, key-frame ratios
    nlohmann::json links;             // the emulator's profiles
    // The co-running measurements behind costs.corun_headset_slowdown and corun_server_slowdown:
    // one side's frames timed alone and beside the other side's mix.
    struct CoRun {
        double alone_ms = 0.0, shared_ms = 0.0;  // a frame's median, alone and beside the load
        int samples = 0;                         // paired frames
        double ratio_p10 = 0.0, ratio_p90 = 0.0;
        double slowdown = 0.0;  // their geometric mean (0: not measured)
        std::string note = "not measured";
    };
    CoRun corun_headset, corun_server;
    std::vector<SpeedSample> speed_probes;  // over the calibration: start, middle, end
    std::string speed_note;                 // why there is no speed reference (empty: there is)
    nlohmann::json toJson() const;
    std::string toToml() const;  // the hardware file (sim/hardware.h grammar), comments included
};

Expected<Calibration> runCalibration(const CalibrateOptions& options);

// The co-running load's child process (`qvr corun-load --mix MIX`): one side's frame mix,
// looped until it is killed, beside the other side's measured frames. Returns an exit code.
int runCoRunLoad(const CalibrateOptions& options, const std::string& mix);

// The machine's speed at one moment: a fixed headset frame and a fixed server frame (the
// co-running measurement's frames at kCoRunE1Deg: both eyes' fovea, four decodes and UCA; four
// periphery layers rendered and encoded), each timed over the same frames every time on this
// thread's core, their medians. `qvr calibrate` takes it three times over its measurement and
// keeps the mean as the hardware file's speed reference; `qvr run` takes it before and after
// each design, reports how far it moved, and predicts each design a second time with its costs
// at the ratio (docs/MODEL.md §11). Nothing in it is a run's
// measurement.
class SpeedProbe {
public:
    static constexpr int kFrames = 12;
    // Its own renderer and the calibration's poses for these options; the caller's thread and
    // core are the ones it measures.
    static Expected<std::unique_ptr<SpeedProbe>> make(const CalibrateOptions& options);
    ~SpeedProbe();
    Expected<SpeedSample> measure();
    struct Impl;

private:
    explicit SpeedProbe(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

// A key for this machine and these options (CPU model, cores, profile, scene, codec, LOD); the
// cached calibration of `qvr run` is stored under it.
std::string calibrationCacheKey(const CalibrateOptions& options);
std::string calibrationCachePath(const CalibrateOptions& options);
// What `qvr calibrate` prints once it has measured: a line per part (samples, spread, fit
// residual, law), then the frame's overhead, the codec's laws, the co-running and the speed
// reference.
std::string calibrationSummaryText(const Calibration& cal);
// A part's fitted law as text: "a + b·Mpx + c·ktri" or "k·Mpx^p·ktri^q", with its whole-frame
// scale.
std::string costLawText(const PartCost& cost);
// The codec's frame-by-frame bits in a line: how many frames, and the middle's and outer's mean
// over the law in the motion's first second (frames up to 30) and after it, with their range.
std::string bitsByFrameText(const RuntimeCosts& costs);

// "h/s, h/s … ms headset/server" of speed probes.
std::string speedProbesText(const std::vector<SpeedSample>& probes);
// Each side's mean over the probes; zero for none.
SpeedSample meanSpeed(const std::vector<SpeedSample>& probes);
// Each side's spread of speed probes (headset, server): largest over smallest, minus 1, in
// percent; {0, 0} with fewer than two probes.
std::array<double, 2> speedProbesSpreadPct(const std::vector<SpeedSample>& probes);
// Probes further apart than this (or a run this far off its calibration's reference): the
// machine was unsteady (calibrate, run, validate).
inline constexpr double kUnsteadySpeedPct = 10.0;

}  // namespace qvr::experiment
