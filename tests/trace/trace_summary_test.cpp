// What `qvr trace motion|gaze` report: turning speed and gaze events counted from the trace.
#include <gtest/gtest.h>

#include "qvr/trace/trace_summary.h"

namespace qvr {
namespace {

TEST(TraceSummary, HeadTurnIsTheAngleBetweenPosesTimesTheRate) {
    PoseTrace trace;
    for (int i = 0; i < 3; ++i) {
        PoseSample s;
        s.t_ms = i * 10.0;
        // 1 degree then 3 degrees of yaw between consecutive poses.
        s.pose.orientation = quatFromEulerDeg({i == 0 ? 0.0 : (i == 1 ? 1.0 : 4.0), 0.0, 0.0});
        trace.samples.push_back(s);
    }
    const HeadTurnStats turn = headTurnStats(trace, 100.0);
    EXPECT_NEAR(turn.mean_deg_s, 200.0, 1e-3);
    EXPECT_NEAR(turn.max_deg_s, 300.0, 1e-3);
    EXPECT_EQ(headTurnStats(PoseTrace{}, 100.0).mean_deg_s, 0.0);
}

TEST(TraceSummary, GazeEventsAreCountedByKind) {
    GazeTrace trace;
    trace.samples.push_back({0.0, {}});
    trace.samples.push_back({2000.0, {}});
    GazeEvent e;
    e.kind = GazeEventKind::kSaccade;
    e.amplitude_deg = 4.0;
    trace.events = {e, e, {}, {}};
    trace.events[1].amplitude_deg = 8.0;
    trace.events[3].kind = GazeEventKind::kPursuit;
    const GazeEventCounts c = countGazeEvents(trace);
    EXPECT_EQ(c.saccades, 2);
    EXPECT_EQ(c.fixations, 1);
    EXPECT_EQ(c.pursuits, 1);
    EXPECT_DOUBLE_EQ(c.mean_saccade_deg, 6.0);
    EXPECT_EQ(gazeTraceReport(trace, GazeModelConfig{}, 7, "g.csv"),
              "wrote g.csv: 2 samples at 120 Hz (2.00 s), seed 7: 1 fixations, 1 pursuits, 2 "
              "saccades (mean amplitude 6.0 deg)\n");
}

}  // namespace
}  // namespace qvr
