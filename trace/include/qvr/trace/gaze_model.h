// A seeded gaze model for the foveated pipeline (paper §3.1 places the fovea at the gaze; §7:
// eye trackers sample at 120 Hz): fixations, saccades on the main sequence, optional smooth
// pursuit, and the CSV gaze-trace format both ways.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/foveation/eye_geometry.h"

namespace qvr {

struct GazeModelConfig {
    double sample_rate_hz = 120.0;  // eye-tracker rate (§7: HTC Vive Pro Eye, Tobii)
    // Fixation durations: log-normal, median and spread, clamped (free viewing: 200–300 ms).
    double fixation_median_ms = 250.0;
    double fixation_sigma = 0.45;
    double fixation_min_ms = 80.0;
    double fixation_max_ms = 1500.0;
    // Saccade amplitudes: log-normal, median and spread, clamped (most are below 15°).
    double saccade_median_deg = 6.0;
    double saccade_sigma = 0.7;
    double saccade_min_deg = 0.5;
    double saccade_max_deg = 35.0;
    // Main sequence: duration = slope·A + intercept; peak velocity = vmax·(1 − exp(−A/c)).
    double duration_slope_ms_per_deg = 2.2;
    double duration_intercept_ms = 21.0;
    double peak_velocity_max_deg_s = 500.0;
    double peak_velocity_c_deg = 7.0;
    // Smooth pursuit in place of a fixation with this probability, at a log-normal speed.
    double pursuit_probability = 0.0;
    double pursuit_median_deg_s = 10.0;
    double pursuit_max_deg_s = 30.0;
    // Gaze stays inside this ellipse around the optical axis (people turn the head beyond it).
    double bound_x_deg = 25.0;
    double bound_y_deg = 20.0;
    // Eye-tracker noise (Gaussian, per sample, per axis); 0 gives the eye's true path.
    double tracker_noise_deg = 0.0;
};

enum class GazeEventKind { kFixation, kSaccade, kPursuit };

struct GazeEvent {
    GazeEventKind kind = GazeEventKind::kFixation;
    double start_ms = 0.0;
    double duration_ms = 0.0;
    Gaze from;
    Gaze to;                     // fixations: to == from
    double amplitude_deg = 0.0;  // distance from → to
    double peak_velocity_deg_s = 0.0;
};

struct GazeSample {
    double t_ms = 0.0;
    Gaze gaze;
};

struct GazeTrace {
    std::vector<GazeSample> samples;  // strictly increasing t_ms
    std::vector<GazeEvent> events;    // the model's ground truth (empty for traces read back)
};

Status validateGazeModelConfig(const GazeModelConfig& config);

// The main-sequence saccade of amplitude A: duration and peak velocity.
double saccadeDurationMs(const GazeModelConfig& config, double amplitude_deg);
double saccadePeakVelocityDegS(const GazeModelConfig& config, double amplitude_deg);
// Fraction of the amplitude covered at fraction tau ∈ [0, 1] of the duration: a plateau
// velocity profile with raised-cosine ramps whose peak/mean ratio meets the main sequence.
double saccadeProgress(const GazeModelConfig& config, double amplitude_deg, double tau);

// `samples` tracker samples from t = 0 at sample_rate_hz; the same seed gives the same trace.
Expected<GazeTrace> generateGaze(const GazeModelConfig& config, uint64_t seed, int samples);

// The gaze a renderer sees at t_ms: the newest sample at or before it (sample and hold, as a
// tracker delivers); the first sample before the trace starts. The trace must not be empty.
Gaze gazeAt(const GazeTrace& trace, double t_ms);

// CSV: header "t_ms,x_deg,y_deg", one sample per line; angles as in Gaze (right/up positive).
std::string gazeTraceToCsv(const GazeTrace& trace);
Status writeGazeCsv(const GazeTrace& trace, const std::string& path);
// Strict: exact header, 3 finite fields, increasing times, angles within ±90°. Errors name the
// line.
Expected<GazeTrace> parseGazeCsv(std::string_view text, std::string_view source_name = "csv");
Expected<GazeTrace> loadGazeCsv(const std::string& path);

}  // namespace qvr
