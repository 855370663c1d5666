// The summary a `qvr run --headsets` child sends its parent survives the trip.
#include "../../experiment/src/headset_child.h"

#include <gtest/gtest.h>

#include "qvr/runtime/telemetry.h"

namespace qvr::experiment {
namespace {

TEST(HeadsetChildSummary, RoundTripsEverySentField) {
    runtime::DesignSummary s;
    s.design = "qvr";
    s.frames = 300;
    s.frames_displayed = 290;
    s.frames_reused = 10;
    s.frames_new_layers = 280;
    s.frames_remote_requested = 299;
    s.fps_mean = 71.5;
    s.mtp_ms_mean = 18.25;
    s.mtp_ms_p99 = 31.0;
    s.bytes_per_frame_mean = 12345.0;
    s.e1_deg_mean = 9.5;
    s.t_local_ms_mean = 6.5;
    s.t_remote_ms_mean = 11.75;
    s.headset_busy_ms_mean = 7.25;
    s.warmup_frames = 12;
    s.startup_unfinished = true;
    const nlohmann::json j = summaryToJson(s);
    EXPECT_EQ(j.size(), 16u);
    const runtime::DesignSummary back = summaryFromJson(j);
    EXPECT_EQ(back.design, "qvr");
    EXPECT_EQ(back.frames, 300);
    EXPECT_EQ(back.frames_displayed, 290);
    EXPECT_EQ(back.frames_reused, 10);
    EXPECT_EQ(back.frames_new_layers, 280);
    EXPECT_EQ(back.frames_remote_requested, 299);
    EXPECT_DOUBLE_EQ(back.fps_mean, 71.5);
    EXPECT_DOUBLE_EQ(back.mtp_ms_mean, 18.25);
    EXPECT_DOUBLE_EQ(back.mtp_ms_p99, 31.0);
    EXPECT_DOUBLE_EQ(back.bytes_per_frame_mean, 12345.0);
    EXPECT_DOUBLE_EQ(back.e1_deg_mean, 9.5);
    EXPECT_DOUBLE_EQ(back.t_local_ms_mean, 6.5);
    EXPECT_DOUBLE_EQ(back.t_remote_ms_mean, 11.75);
    EXPECT_DOUBLE_EQ(back.headset_busy_ms_mean, 7.25);
    EXPECT_EQ(back.warmup_frames, 12);
    EXPECT_TRUE(back.startup_unfinished);
}

TEST(HeadsetChildSummary, MissingKeysReadAsZero) {
    const runtime::DesignSummary s = summaryFromJson(nlohmann::json{{"frames", 5}});
    EXPECT_EQ(s.design, "");
    EXPECT_EQ(s.frames, 5);
    EXPECT_DOUBLE_EQ(s.fps_mean, 0.0);
    EXPECT_FALSE(s.startup_unfinished);
}

}  // namespace
}  // namespace qvr::experiment
