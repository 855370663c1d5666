// trace.json: the server's stamps file is parsed strictly, the clock offset between server and
// headset is recovered from the round trips, and the written timeline holds every frame's stages
// in order on the headset's clock.
#include "qvr/runtime/chrome_trace.h"

#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

namespace qvr::runtime {
namespace {

namespace fs = std::filesystem;

fs::path tempPath(const std::string& name) {
    return fs::temp_directory_path() / ("qvr-trace-" + std::to_string(getpid()) + "-" + name);
}

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kOrigin = 1'000'000 * kMs;  // the headset's clock at the design's start
constexpr int64_t kServerAhead = 7 * kMs;     // server clock − headset clock
constexpr int64_t kUp = 2 * kMs, kDown = 3 * kMs;

// Frames every 11 ms: pose, decision, request, fovea render, two streams, UCA, scan-out; and the
// server's stamps for them, its clock kServerAhead ahead.
void makeRun(int frames, std::vector<FrameTelemetry>& telemetry,
             std::vector<ServerFrameStamps>& server) {
    for (int k = 0; k < frames; ++k) {
        FrameTelemetry t;
        const int64_t base = k * 11 * kMs;
        t.frame = k;
        t.pose_ns = base;
        t.decision_ns = base + kMs / 2;
        t.request_ns = base + kMs;
        t.remote_requested = true;
        t.local_start_ns = base + kMs + kMs / 10;
        t.local_end_ns = base + 4 * kMs;
        ServerFrameStamps s;
        s.client = 9;
        s.frame_id = uint32_t(k);
        s.client_send_ns = uint64_t(kOrigin + t.pose_ns);
        s.queued_ns = kOrigin + t.request_ns + kServerAhead + kUp + (k % 3) * kMs / 10;
        s.start_ns = s.queued_ns + kMs / 5;
        int64_t at = s.start_ns;
        for (uint8_t sid : {uint8_t{0}, uint8_t{2}}) {
            // 1000 pixels shading (k + 1)·(sid + 1) fragments each; frame 5's right eye uncounted.
            const int64_t fragments = k == 5 && sid == 2 ? -1 : 1000 * (k + 1) * (sid + 1);
            ServerFrameStamps::Layer l{
                sid, at, at + 2 * kMs, at + 3 * kMs, at + 3 * kMs + 10'000, 1000, fragments};
            s.layers.push_back(l);
            at = l.sent_ns;
            t.stream_rx_ns[sid] = l.sent_ns - kOrigin - kServerAhead + kDown + (k % 2) * kMs / 10;
            t.stream_decoded_ns[sid] = t.stream_rx_ns[sid] + kMs;
        }
        s.end_ns = at;
        t.uca_start_ns = std::max(t.stream_decoded_ns[0], t.stream_decoded_ns[2]);
        t.uca_end_ns = t.uca_start_ns + kMs;
        t.display_ns = t.uca_end_ns + kMs;
        telemetry.push_back(t);
        server.push_back(s);
    }
}

TEST(ChromeTrace, EstimatesTheServerClockOffsetWithinItsBound) {
    std::vector<FrameTelemetry> telemetry;
    std::vector<ServerFrameStamps> server;
    makeRun(30, telemetry, server);
    const std::vector<TraceDesign> designs = {{"qvr", kOrigin, 90.0, &telemetry}};
    const ClockOffset c = estimateClockOffset(designs, server);
    EXPECT_EQ(c.requests, 30);
    // Up from the decision, 0.5 ms before the request: (min up − min down) / 2 =
    // (7 + 2.5 − (−7 + 3)) / 2 = 6.75 ms, ± 2.75 ms: covers the true 7.
    EXPECT_NEAR(double(c.offset_ns), 6.75 * kMs, 1e3);
    EXPECT_NEAR(double(c.bound_ns), 2.75 * kMs, 1e3);
    EXPECT_LE(std::abs(c.offset_ns - double(kServerAhead)), c.bound_ns);
}

TEST(ChromeTrace, SumsTheServersRenderAndEncodePerDesign) {
    // Two layers a frame, each 3 ms from render start to encode end: 6 ms a frame for the
    // design whose requests they served; none for a design that requested nothing matched; a
    // stamp for no known request (another headset) counts nowhere.
    std::vector<FrameTelemetry> telemetry;
    std::vector<ServerFrameStamps> server;
    makeRun(30, telemetry, server);
    std::vector<FrameTelemetry> other = telemetry;
    for (FrameTelemetry& t : other)
        t.remote_requested = false;
    ServerFrameStamps stray = server.front();
    stray.client_send_ns += 1;
    server.push_back(stray);
    const std::vector<TraceDesign> designs = {{"qvr", kOrigin, 90.0, &telemetry},
                                              {"local", kOrigin + 5000 * kMs, 90.0, &other}};
    const std::vector<ServerBusy> busy = serverBusyPerDesign(designs, server);
    ASSERT_EQ(busy.size(), 2u);
    EXPECT_EQ(busy[0].frames, 30);
    EXPECT_NEAR(busy[0].busy_ms_mean, 6.0, 1e-9);
    EXPECT_EQ(busy[1].frames, 0);
    EXPECT_EQ(busy[1].busy_ms_mean, 0.0);
    // Each layer's fragments per pixel by frame id and stream; -1 where none was counted.
    ASSERT_EQ(busy[0].fragments_per_px.size(), 30u);
    for (size_t k : {size_t(0), size_t(5), size_t(29)}) {
        EXPECT_EQ(busy[0].fragments_per_px[k][0], double(k + 1)) << k;
        EXPECT_EQ(busy[0].fragments_per_px[k][1], -1.0) << k;
        EXPECT_EQ(busy[0].fragments_per_px[k][2], k == 5 ? -1.0 : 3.0 * double(k + 1)) << k;
    }
    EXPECT_TRUE(busy[1].fragments_per_px.empty());
}

TEST(ChromeTrace, WritesEveryFramesStagesInOrderOnTheHeadsetClock) {
    std::vector<FrameTelemetry> telemetry;
    std::vector<ServerFrameStamps> server;
    makeRun(20, telemetry, server);
    const fs::path path = tempPath("ok.json");
    auto info = writeChromeTrace(path.string(), {{"qvr", kOrigin, 90.0, &telemetry}}, server, 15);
    ASSERT_TRUE(info) << info.error();
    EXPECT_EQ(info->frames_written, 15);
    EXPECT_EQ(info->frames_left_out, 5);
    EXPECT_EQ(info->server_frames_matched, 15);
    std::ifstream in(path);
    const nlohmann::json j = nlohmann::json::parse(in);
    // frame → stage → (start, end) in µs
    std::map<int64_t, std::map<std::string, std::pair<double, double>>> stages;
    int flows_start = 0, flows_end = 0;
    for (const auto& e : j["traceEvents"]) {
        if (e["ph"] == "s")
            ++flows_start;
        if (e["ph"] == "f")
            ++flows_end;
        if (e["ph"] != "X")
            continue;
        const std::string name = e["name"];
        const std::string stage = name.substr(0, name.find(' '));
        const double ts = e["ts"], dur = e["dur"];
        ASSERT_GE(dur, 0.0) << name;
        auto& slot = stages[e["args"]["frame"]][stage + (e["pid"] == 2 ? "@server" : "")];
        slot = slot.second == 0
                   ? std::make_pair(ts, ts + dur)
                   : std::make_pair(std::min(slot.first, ts), std::max(slot.second, ts + dur));
    }
    EXPECT_EQ(flows_start, 15);
    EXPECT_EQ(flows_end, 15);
    ASSERT_EQ(stages.size(), 15u);
    for (const auto& [k, s] : stages) {
        const std::vector<std::string> order = {
            "decide",      "request", "queued@server", "render@server", "encode@server",
            "send@server", "receive", "decode",        "UCA",           "scan-out"};
        for (size_t i = 0; i < order.size(); ++i)
            ASSERT_TRUE(s.count(order[i])) << "frame " << k << " has no " << order[i];
        for (size_t i = 1; i < order.size(); ++i)
            EXPECT_LE(s.at(order[i - 1]).first, s.at(order[i]).first + 1e-3)
                << "frame " << k << ": " << order[i - 1] << " starts after " << order[i];
        // Shifted onto the headset clock, the server works after the request and before the
        // headset receives.
        EXPECT_GE(s.at("queued@server").first, s.at("request").first) << k;
        EXPECT_LE(s.at("send@server").second, s.at("receive").second + 1e-3) << k;
    }
    fs::remove(path);
}

TEST(ChromeTrace, ReadsItsStampsFileAndRejectsMalformedOnes) {
    const fs::path path = tempPath("stamps.csv");
    {
        std::ofstream f(path);
        f << kServerStampsHeader << "3,7,100,200,210,400,0,211,250,300,301,4096,20480\n"
          << "3,7,100,200,210,400,2,302,350,390,399,4096,-1\n"
          << "18181381301805239764,8,111,500,510,600,1,511,550,590,599,1024,3000\n";
    }
    auto read = readServerStamps(path.string());
    ASSERT_TRUE(read) << read.error();
    ASSERT_EQ(read->size(), 2u);
    EXPECT_EQ((*read)[0].layers.size(), 2u);
    EXPECT_EQ((*read)[0].layers[1].stream_id, 2);
    EXPECT_EQ((*read)[1].frame_id, 8u);
    EXPECT_EQ((*read)[1].client, 18181381301805239764ull);  // ids use all 64 bits
    EXPECT_EQ((*read)[0].layers[0].pixels, 4096);
    EXPECT_EQ((*read)[0].layers[0].fragments, 20480);
    EXPECT_EQ((*read)[0].layers[1].fragments, -1);  // not counted
    EXPECT_EQ((*read)[1].layers[0].fragments, 3000);
    for (const std::string bad : {"3,7,100,200,210,400,0,211,250,300,301,4096\n",
                                  "3,7,100,200,210,400,9,211,250,300,301,4096,1\n",
                                  "3,7,100,200,x,400,0,211,250,300,301,4096,1\n",
                                  "3,7,100,200,210,400,0,211,250,300,301,4096,1,5\n",
                                  "3,-7,100,200,210,400,0,211,250,300,301,4096,1\n",
                                  "3,7,100,200,210,400,0,211,250,300,301,-4,1\n",
                                  "3,7,100,200,210,400,0,211,250,300,301,11\n",
                                  "3,7,100,200,210,400,0,211,250,300,301,4096,-2\n",
                                  "3,7,100,200,210,400,0,211,250,300,301,-1,5\n"}) {
        std::ofstream(path) << kServerStampsHeader << bad;
        auto r = readServerStamps(path.string());
        ASSERT_FALSE(r) << bad;
        EXPECT_NE(r.error().find(":2:"), std::string::npos) << r.error();
    }
    std::ofstream(path) << "not,a,header\n";
    EXPECT_FALSE(readServerStamps(path.string()));
    EXPECT_FALSE(readServerStamps("/nonexistent-dir/stamps.csv"));
    fs::remove(path);
}

TEST(ChromeTrace, FailsWithAMessageOnAnUnwritablePath) {
    std::vector<FrameTelemetry> telemetry;
    std::vector<ServerFrameStamps> server;
    makeRun(2, telemetry, server);
    auto r = writeChromeTrace("/nonexistent-dir/trace.json", {{"qvr", kOrigin, 90.0, &telemetry}},
                              server);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("/nonexistent-dir/trace.json"), std::string::npos);
}

}  // namespace
}  // namespace qvr::runtime
