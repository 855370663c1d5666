// summary.json's shared keys (core/run_summary_json.h) and the Table 1 link efficiency
// (core/link_efficiency.h), each in its one home.
#include <gtest/gtest.h>

#include "qvr/core/link_efficiency.h"
#include "qvr/core/run_summary_json.h"

namespace qvr {
namespace {

TEST(RunStatsJson, SpellsTheHeadlineStatisticsWithTheirValues) {
    RunStats s;
    s.frames = 120;
    s.frames_reused = 7;
    s.frames_new_layers = 100;
    s.fps_mean = 71.5;
    s.mtp_ms_mean = 40.25;
    s.mtp_ms_p99 = 80.5;
    s.bytes_per_frame_mean = 12345.0;
    s.e1_deg_mean = 9.5;
    s.frames_displayed = 99;  // not a headline key: each summary adds what it has
    const nlohmann::json j = runStatsJson(s);
    EXPECT_EQ(j.size(), 8u);
    EXPECT_EQ(j["frames"], 120);
    EXPECT_EQ(j["frames_reused"], 7);
    EXPECT_EQ(j["frames_new_layers"], 100);
    EXPECT_EQ(j["fps_mean"], 71.5);
    EXPECT_EQ(j["mtp_ms_mean"], 40.25);
    EXPECT_EQ(j["mtp_ms_p99"], 80.5);
    EXPECT_EQ(j["bytes_per_frame_mean"], 12345.0);
    EXPECT_EQ(j["e1_deg_mean"], 9.5);
    EXPECT_FALSE(j.contains("frames_displayed"));
}

TEST(LinkEfficiency, IsTheLeastSquaresFitOfTable1AtWifisNominalRate) {
    const double eta = calibratedLinkEfficiency();
    EXPECT_NEAR(eta, 0.6872, 1e-4);
    // Every row's T_remote within 1.3% of bits / (η · 200 Mbit/s).
    ASSERT_EQ(table1Rows().size(), 5u);
    for (const Table1Row& r : table1Rows()) {
        const double t_ms = r.background_bytes * 8.0 / (eta * 200e6) * 1e3;
        EXPECT_NEAR(t_ms, r.t_remote_ms, 0.013 * r.t_remote_ms) << r.app;
    }
}

}  // namespace
}  // namespace qvr
