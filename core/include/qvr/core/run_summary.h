// One run's frames and their statistics, as every pipeline reports them: the runtime's telemetry
// (runtime/telemetry.h), the simulator's model of the runtime (sim/runtime_model.h) and the
// paper simulator (sim/simulator.h) all go through here, so a p99 means the same statistic on
// both sides.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

namespace qvr {

// THE percentile of qvr: nearest rank. The p-th percentile of n values is the value at rank
// ceil(p / 100 · n) (1-based, at least 1) of the sorted sample — always a value that was
// observed, never an interpolation between two. p in (0, 100]; 0 for an empty sample. With 150
// frames the p99 is the second-worst frame, with 100 or fewer the worst; the median (p = 50) of
// an even count is the lower of the two middle values.
double percentile(std::vector<double> values, double p);

// The longest start-up a summary holds back (frames): a design that asks the server for layers
// starts up until the first of them is on screen, at most this many frames.
inline constexpr size_t kMaxStartupFrames = 4096;

// One frame as a run summary reads it; times in ms from the run's start.
struct FrameSample {
    double pose_ms = 0.0;      // the frame's pose was sampled: it starts
    double display_ms = -1.0;  // the vsync slot it was scanned out at; < 0: not displayed
    double mtp_ms = 0.0;       // pose sample → composed image ready
    double bytes = 0.0;        // media payload received for it
    double e1_deg = 0.0;
    double t_local_ms = 0.0;
    double t_remote_ms = 0.0;      // counted where remote_requested
    double headset_busy_ms = 0.0;  // counted where > 0 (the first frame of a session has none)
    double uca_ms = 0.0;
    bool remote_requested = false;
    bool remote_withheld = false;  // it would have asked, but the request window was full
    // Some layers from the server have been on screen by this frame: a design that asks for
    // layers has finished its start-up only then.
    bool remote_shown = true;
    bool reused = false;  // the display re-warped older layers
    // The frame whose server layers were on screen (−1: none yet). A reused frame that shows a
    // late frame's layers for the first time shows new content; one that re-warps the same
    // layers again does not.
    int64_t shown_frame = -1;
    bool fallback_local = false;  // the server was gone: everything rendered locally
};

// The statistics of one run, over its frames after the start-up.
struct RunStats {
    int frames = 0;
    int frames_displayed = 0;
    int frames_reused = 0;
    // Counted frames that put server layers on screen newer than any shown before (late ones
    // included), and counted frames that asked for layers: a design that asked and showed none
    // new re-warped the same old periphery the whole time (qvr run exits 1).
    int frames_new_layers = 0;
    int frames_remote_requested = 0;
    double fps_mean = 0.0;  // displayed frames per second of scan-out, first to last display
    double mtp_ms_mean = 0.0;
    double mtp_ms_p99 = 0.0;  // percentile(…, 99)
    double bytes_per_frame_mean = 0.0;
    double e1_deg_mean = 0.0;
    double t_local_ms_mean = 0.0;
    // The headset's busy time per frame over the counted frames that have one;
    // headset_busy_frames 0: no mean.
    double headset_busy_ms_mean = 0.0;
    int headset_busy_frames = 0;
    double t_remote_ms_mean = 0.0;  // over frames that requested remote layers
    double uca_ms_mean = 0.0;
    double frames_fallback_local = 0;
    double wall_s = 0.0;  // the first counted frame's pose to the last one's display
    // The session's first frames (connection, the server's first render and key frame, first
    // use of every code path) are its start-up, not its steady state: they are left out of
    // every statistic above and their worst MTP is reported on its own. For a design that asks
    // the server for layers, the start-up lasts at least until the first of them is on screen
    // (FrameSample::remote_shown), at most kMaxStartupFrames: a server whose first frame takes
    // longer than the wait limit leaves the headset re-warping nothing at the refresh rate, and
    // those frames are not the design's steady state. warmup_frames is the number of frames the
    // start-up took.
    int warmup_frames = 0;
    double startup_mtp_ms_max = 0.0;
    // No frame came past the start-up: the design asked for the server's layers and none of them
    // reached the screen (or the run was not longer than the warm-up). The statistics are then
    // over every frame, and a reader must not take them for the design's steady state.
    bool startup_unfinished = false;
};

// RunStats one frame at a time in display order, in memory that does not grow with the run (a
// `qvr client` may run for hours): the MTP p99 is exact over the first exact_mtp_frames frames
// (kExactMtpFrames unless told; a caller that holds every frame anyway may ask for all of them)
// and beyond that read from a log-spaced histogram (relative error ≤ 0.05%). The start-up is the
// first warmup_frames frames and, after them, every frame that requested layers while none had
// been shown (RunStats::warmup_frames).
class FrameSummarizer {
public:
    static constexpr size_t kExactMtpFrames = size_t{1} << 16;

    explicit FrameSummarizer(int warmup_frames, size_t exact_mtp_frames = kExactMtpFrames);
    void add(const FrameSample& f);
    RunStats finish() const;

private:
    void count(const FrameSample& f, bool new_layers);
    double mtpP99() const;

    RunStats m_s;
    size_t m_warmup = 0;
    size_t m_exact_mtp_frames = kExactMtpFrames;
    // The first warmup frames wait here until a later one proves they were the start-up (a run
    // of no more frames than that is summarized whole).
    std::vector<FrameSample> m_startup;
    bool m_startup_done = false;
    double m_mtp_sum = 0.0, m_bytes = 0.0, m_e1 = 0.0, m_t_local = 0.0, m_t_remote = 0.0;
    double m_busy = 0.0;
    double m_uca = 0.0;
    int m_remote_frames = 0;
    double m_first_display_ms = -1.0, m_last_display_ms = -1.0;
    double m_first_pose_ms = 0.0, m_last_frame_display_ms = 0.0;
    std::vector<double> m_mtp_exact;   // while no more than kExactMtpFrames
    std::vector<uint32_t> m_mtp_hist;  // after that (fixed size)
    double m_mtp_min = 0.0, m_mtp_max = 0.0;
    int64_t m_newest_shown = -1;  // over every frame, the start-up's too
};

// FrameSummarizer over a vector.
RunStats summarizeFrames(const std::vector<FrameSample>& frames, int warmup_frames);

// The frames per second shown with their own layers: fps_mean × (frames − frames_reused) /
// frames (a reused frame re-warped an older periphery). What `qvr sweep` judges designs on and
// `qvr run`'s stale-periphery warning prints; fps_mean itself when no frame was counted.
inline double ownLayersFps(double fps_mean, int frames, int frames_reused) {
    if (frames <= 0)
        return fps_mean;
    const int reused = frames_reused < 0 ? 0 : frames_reused > frames ? frames : frames_reused;
    return fps_mean * double(frames - reused) / double(frames);
}

// Whether fixed design a beats b for "the best fixed e1": more frames a second with their own
// layers; the display's pacing makes equal rates common (two designs showing 89 frames over the
// same vsyncs), so a tie goes to the lower MTP p99, then to the name, whatever order they ran in.
// `qvr sweep` and `qvr run`'s best_fixed both choose by it.
inline bool beatsForBestFixed(double own_fps_a, double mtp_p99_a, const std::string& name_a,
                              double own_fps_b, double mtp_p99_b, const std::string& name_b) {
    if (own_fps_a != own_fps_b)
        return own_fps_a > own_fps_b;
    return std::tie(mtp_p99_a, name_a) < std::tie(mtp_p99_b, name_b);
}

}  // namespace qvr
