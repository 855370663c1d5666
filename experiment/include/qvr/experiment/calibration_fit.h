// The fit of a calibration (calibration.h): the micro-benchmarks' raw samples in, this machine's
// RuntimeCosts (sim/hardware.h) and the parts' summaries out. Nothing here measures, so every
// step runs on any samples (synthetic ones in tests).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "qvr/experiment/calibration.h"
#include "qvr/sim/cost_fit.h"

namespace qvr::experiment {

// One P-frame coded twice: by its stream's snug encoder and by one whose canvas began 1.25×
// as wide and high, as a run's stream's does after e1 grew.
struct PaddingSample {
    double extra = 0.0;  // the padded canvas's pixels over the snug canvas's, − 1
    double ratio = 0.0;  // the padded frame's bytes over the snug frame's
};

// What the micro-benchmarks measured, part by part.
struct CalibrationSamples {
    std::vector<CostSample> decision;             // cluster ring counts, both eyes
    std::vector<double> plan_ms;                  // a frame's plan and bookkeeping
    std::vector<CostSample> fovea;                // one eye's fovea or full-frame pass
    std::vector<CostSample> server_render;        // one periphery or whole-frame layer
    std::vector<CostSample> encode;               // one layer or whole frame, in a running stream
    std::vector<CostSample> decode;               // one stream's P-frame, in a headset frame
    std::vector<CostSample> uca;                  // one frame, both eyes
    std::vector<double> video_copy_ms;            // the display video's copy right after UCA
    std::array<std::vector<BitsSample>, 2> bits;  // the layers' P-frames: middle, outer
    // Frame k of the codec pass's motion: its content key (workload.h frameContentKey).
    std::vector<double> frame_content_key;
    std::vector<PaddingSample> padding;
    // A new encoder's key frame over its stream's mean P-frame: middle, outer.
    std::array<std::vector<double>, 2> keyframe_ratio;
    std::vector<double> periodic_keyframe_ratio;  // the key frame at keyint_frames, both layers
    std::vector<double> full_frame_bits_per_px;   // remote's whole-frame P-frames
};

// The middle value of v (the upper of the two middle ones for an even count); 0 for none.
double upperMedian(std::vector<double> v);
// The mean of v; 0 for none.
double meanOf(const std::vector<double>& v);

// A part's summary: its samples' spread, the fit's residual and every sample (for the JSON).
CalibratedPart summarisePart(const std::string& name, const std::string& what,
                             const std::vector<CostSample>& samples, const PartCost& cost);

// Least squares through the origin of bytes ratio − 1 = ρ · extra canvas share, ρ in [0, 10];
// 0 without samples.
double fitPaddingBitsRatio(const std::vector<PaddingSample>& samples);

// Frame by frame: what each motion frame's layers spent, over every e1 and both eyes, over what
// costs' bits law gives the same layers, for the frames whose middle and outer both spent bits
// (the others keep the law alone); trailing law-only frames are dropped.
void fitBitsByFrame(const std::array<std::vector<BitsSample>, 2>& bits,
                    const std::vector<double>& frame_content_key, RuntimeCosts& costs);

// Every part's law, the bits laws, the key frames and padding into cal.costs, the parts'
// summaries into cal.parts (decision, fovea/local, server render, encode, decode, uca) and the
// sample counts beside them.
void fitCalibration(const CalibrationSamples& samples, Calibration& cal);

// One side's frames, timed in pairs of blocks: alone, then beside the other side's load.
struct CoRunPairs {
    std::vector<double> alone_ms;
    std::vector<double> shared_ms;  // shared_ms[j] is alone_ms[j]'s frame beside the load
};

// The co-running slowdown of `side`'s frames beside `load_side`'s on core `load_core`: the
// geometric mean of shared over alone, clamped to [1, 4], with the medians, p10 and p90 of
// the ratios and a note saying so. At least one pair.
Calibration::CoRun fitCoRun(const CoRunPairs& pairs, const std::string& side, int load_core,
                            const std::string& load_side);

// The link's part of the costs: net's packet payload and header, and net's link profiles.
void describeLinks(Calibration& cal);

}  // namespace qvr::experiment
