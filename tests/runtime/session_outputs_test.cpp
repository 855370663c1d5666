// What a runtime session writes (runtime/session_outputs.h): the client's summary.json keys and
// values, the server's counters, frames CSV and printed lines.
#include "qvr/runtime/session_outputs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace qvr::runtime {
namespace {

namespace fs = std::filesystem;

fs::path tempPath(const std::string& name) {
    return fs::temp_directory_path() / ("qvr-outputs-" + std::to_string(getpid()) + "-" + name);
}

HeadsetResult someResult() {
    HeadsetResult r;
    r.origin_ns = 123456789;
    r.summary.design = "qvr";
    r.summary.frames = 10;
    r.summary.frames_displayed = 9;
    r.summary.frames_reused = 2;
    r.summary.fps_mean = 88.0;
    r.summary.frames_fallback_local = 1;
    r.stats.connects = 1;
    r.stats.late_frames = 3;
    r.stats.requests_withheld = 7;
    r.stats.key_frame_requests = 4;
    r.stats.net.key_frame_requests_sent = 5;
    r.stats.net.control_forged = 2;
    r.stats.net.assembler.nacks = 6;
    r.frames.resize(3);
    r.frames[0].frame = 7;
    return r;
}

TEST(SessionOutputs, ClientSummaryHasTheSharedKeysAndItsOwn) {
    const HeadsetResult r = someResult();
    const nlohmann::json j = clientSummaryJson({"qvr", 300, true, 90.0}, r);
    EXPECT_EQ(j["design"], "qvr");
    EXPECT_EQ(j["frames"], 10);
    EXPECT_EQ(j["frames_requested"], 300);
    EXPECT_EQ(j["frames_displayed"], 9);
    EXPECT_EQ(j["frames_fallback_local"], 1.0);
    EXPECT_EQ(j["fps_mean"], 88.0);
    EXPECT_EQ(j["clock_origin_ns"], 123456789);
    EXPECT_EQ(j["interrupted"], true);
    EXPECT_EQ(j["late_frames"], 3);
    EXPECT_EQ(j["requests_withheld"], 7);
    EXPECT_EQ(j["nacks_sent"], 6);
    EXPECT_EQ(j["control_forged"], 2);
    // The client reports its own key-frame requests; `qvr run` adds the transport's.
    EXPECT_EQ(j["key_frame_requests"], 4);
    EXPECT_EQ(j["capacity_refusals"], 0);  // refusals by a server at its frame-rate floor
    EXPECT_EQ(j.size(), 38u);              // the keys `qvr client` writes
}

TEST(SessionOutputs, ClientWritesTraceAndSummaryAndWarnsOfForgedControl) {
    const fs::path out = tempPath("client");
    fs::create_directories(out);
    const HeadsetResult r = someResult();
    ASSERT_TRUE(writeClientOutputs(out, {"qvr", 300, false, 90.0}, r, {}));
    std::ifstream in(out / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["trace"]["path"], "trace.json");
    EXPECT_EQ(j["trace"]["frames"], 3);
    EXPECT_EQ(j["trace"]["first_frame"], 7);
    EXPECT_TRUE(fs::exists(out / "trace.json"));
    const std::vector<std::string> w = clientWarnings(r.stats);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0], "2 forged and 0 replayed control messages ended connections");
    EXPECT_NE(clientReportLine(r).find("qvr client: qvr fps 88.0"), std::string::npos);
    fs::remove_all(out);
}

TEST(SessionOutputs, TelemetryCsvGetsARowPerFrameFromTheSink) {
    const fs::path path = tempPath("telemetry.csv");
    std::ofstream file;
    HeadsetConfig config;
    ASSERT_TRUE(startTelemetryCsv(path.string(), "ffr", file, config));
    ASSERT_TRUE(config.frame_sink);
    config.frame_sink(FrameTelemetry{});
    config.frame_sink(FrameTelemetry{});
    ASSERT_TRUE(finishTelemetryCsv(path.string(), file));
    std::ifstream in(path);
    int lines = 0;
    for (std::string line; std::getline(in, line);)
        ++lines;
    EXPECT_EQ(lines, 3);
    fs::remove(path);
    EXPECT_FALSE(startTelemetryCsv("/nonexistent-dir/t.csv", "ffr", file, config));
}

TEST(SessionOutputs, ServerWritesItsCountersAndOneRowPerFrame) {
    RenderServerStats s;
    s.requests = 12;
    s.frames_rendered = 10;
    s.net.link.dropped_loss = 3;
    const fs::path stats = tempPath("stats.json"), frames = tempPath("frames.csv");
    std::vector<ServerFrameRecord> records(2);
    records[1].frame_id = 41;
    ASSERT_TRUE(writeServerOutputs({stats.string(), frames.string()}, s, 1, records));
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["requests"], 12);
    EXPECT_EQ(j["core"], 1);
    EXPECT_EQ(j["link"]["dropped_loss"], 3);
    std::ifstream csv(frames);
    std::string header, row0, row1;
    std::getline(csv, header);
    std::getline(csv, row0);
    std::getline(csv, row1);
    EXPECT_EQ(header.rfind("client,frame,e1_deg,received_ns,start_ns,done_ns,pixels0,", 0), 0u);
    EXPECT_EQ(row1.rfind("0,41,", 0), 0u);
    EXPECT_FALSE(writeServerOutputs({"/nonexistent-dir/s.json", ""}, s, 1, records));
    fs::remove(stats);
    fs::remove(frames);
    const std::string report = serverStatsReport(s);
    EXPECT_EQ(report.rfind("qvr server: 12 requests (0 dropped, 0 invalid), 10 frames", 0), 0u);
    EXPECT_EQ(std::count(report.begin(), report.end(), '\n'), 2);
}

}  // namespace
}  // namespace qvr::runtime
