// The downlink models (paper §5, Table 2): the Table 1 calibration, white noise at 20 dB SNR,
// Mahimahi traces (parser on malformed input, rescaling, transfer timing) and profile names.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>

#include "qvr/sim/network.h"

namespace qvr {
namespace {

std::shared_ptr<const MahimahiTrace> shared(const MahimahiTrace& trace) {
    return std::make_shared<const MahimahiTrace>(trace);
}

TEST(Network, CalibrationReproducesTable1WithinAFewPercent) {
    const double eta = calibratedLinkEfficiency();
    EXPECT_GT(eta, 0.66);
    EXPECT_LT(eta, 0.71);
    for (const Table1Row& r : table1Rows()) {
        const double t_ms = r.background_bytes * 8.0 / (eta * 200e6) * 1e3;
        EXPECT_NEAR(t_ms, r.t_remote_ms, 0.03 * r.t_remote_ms) << r.app;
    }
    // The brief's example: 646 KB in 38 ms is about 136 Mbps.
    EXPECT_NEAR(646e3 * 8 / 0.038 / 1e6, 136.0, 0.1);
}

TEST(Network, NoiseFreeTransferIsBytesOverGoodput) {
    NoisyLink link("x", 100e6, 0.5, std::numeric_limits<double>::infinity(), {}, 1);
    EXPECT_EQ(link.noiseSigma(), 0.0);
    const LinkTransfer t = link.transfer(12.0, 1e6);
    EXPECT_NEAR(t.duration_ms, 1e6 * 8 / 50e6 * 1e3, 1e-12);
    EXPECT_NEAR(t.goodput_bps, 50e6, 1e-6);
}

TEST(Network, TwentyDbWhiteNoiseHasTenPercentSpreadAndNoBias) {
    NoisyLink link("x", 200e6, calibratedLinkEfficiency(), 20.0, {}, 42);
    EXPECT_NEAR(link.noiseSigma(), 0.1, 1e-12);
    double sum = 0.0, sum2 = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        // One packet: the per-sample noise itself (larger payloads average it, see
        // eval_model_test.cpp).
        const double g = link.transfer(0.0, 1000.0).goodput_bps / link.meanGoodputBps();
        sum += g;
        sum2 += g * g;
    }
    const double mean = sum / n;
    EXPECT_NEAR(mean, 1.0, 0.005);
    EXPECT_NEAR(std::sqrt(sum2 / n - mean * mean), 0.1, 0.005);
}

// The simulator reads traces with the one reader net's emulator uses (qvr/core/mahimahi.h):
// digits only on a line, so a stamp with spaces around it is refused as net refuses it.
TEST(Mahimahi, ParsesStampsAndRejectsMalformedTraces) {
    auto ok = parseMahimahiTrace("0\n1\n1\r\n5\n\n10\n", "t");
    ASSERT_TRUE(ok.ok()) << ok.error();
    EXPECT_EQ(ok->stamps_ms.size(), 5u);
    EXPECT_EQ(ok->period_ms, 10);
    EXPECT_NEAR(ok->meanBps(), 5 * 1500 * 8 / 0.010, 1e-6);
    for (const char* bad : {"", "\n\n", "0\n", "1\nx\n", "5\n3\n", "-1\n2\n", "1.5\n",
                            "99999999999999999999\n", "2000000000\n", "12abc\n", "1\n 5 \n"}) {
        auto r = parseMahimahiTrace(bad, "bad.down");
        EXPECT_FALSE(r.ok()) << "accepted: '" << bad << "'";
        if (!r.ok()) {
            EXPECT_NE(r.error().find("bad.down"), std::string::npos);
        }
    }
    EXPECT_FALSE(loadMahimahiTrace("/nonexistent/trace.down").ok());
}

TEST(Mahimahi, TraceLinkRescalesAndTimesTransfersByOpportunity) {
    // One packet opportunity per millisecond: 12 Mbps. Rescaled to 24 Mbps every stamp halves.
    std::string text;
    for (int t = 1; t <= 1000; ++t)
        text += std::to_string(t) + "\n";
    auto trace = parseMahimahiTrace(text, "uniform");
    ASSERT_TRUE(trace.ok());
    EXPECT_NEAR(trace->meanBps(), 12e6, 1e-6);
    TraceLink link("uniform", shared(*trace), 24e6, 1.0, {});
    EXPECT_NEAR(link.timeScale(), 0.5, 1e-12);
    // 30 packets from t = 0 leave at 0.5, 1.0, …, 15.0 ms.
    const LinkTransfer t = link.transfer(0.0, 30 * 1500.0);
    EXPECT_NEAR(t.duration_ms, 15.0, 1e-9);
    // The trace loops: starting near its end, the last stamp (500) then the next loop's 0.5
    // and 1.0 carry three packets.
    const LinkTransfer w = link.transfer(499.9, 3 * 1500.0);
    EXPECT_NEAR(w.duration_ms, 501.0 - 499.9, 1e-9);
    // Payload efficiency inflates the packet count.
    TraceLink half("uniform", shared(*trace), 24e6, 0.5, {});
    EXPECT_NEAR(half.transfer(0.0, 30 * 1500.0).duration_ms, 30.0, 1e-9);
    // A payload many loops long costs whole loops (a new session: the trace from its start).
    link.restart();
    EXPECT_NEAR(link.transfer(0.0, 2000.0 * 1500.0 * 3).duration_ms, 3000.0, 1e-9);
}

// Ten bursts of four opportunities at one stamp, 100 ms apart: the shape of a cellular trace
// rescaled to a slow rate.
auto burstTrace() {
    std::string text;
    for (int b = 1; b <= 10; ++b)
        for (int k = 0; k < 4; ++k)
            text += std::to_string(100 * b) + "\n";
    return parseMahimahiTrace(text, "bursts");
}

TEST(Mahimahi, TraceLinkQueuesLikeTheEmulatorInsideABurst) {
    // Layers sent back to back share a burst, as the emulator's packets do; the model once let
    // only the first layer use it (a start at a burst's instant saw only later opportunities),
    // so a four-layer frame waited for four bursts.
    auto trace = burstTrace();
    ASSERT_TRUE(trace.ok());
    TraceLink link("bursts", shared(*trace), trace->meanBps(), 1.0, {});
    // The first transfer starts the trace: its burst is 100 ms later.
    EXPECT_NEAR(link.transfer(0.0, 1000.0).duration_ms, 100.0, 1e-9);
    // Queued at that burst's instant, three more layers leave in it.
    for (int layer = 0; layer < 3; ++layer)
        EXPECT_NEAR(link.transfer(100.0, 1000.0).duration_ms, 0.0, 1e-5) << layer;
    // The burst's 6,000 bytes are spent (4,000 used, 2,000 left in its last two opportunities:
    // bytes share opportunities); 3,000 more leave in the next burst.
    EXPECT_NEAR(link.transfer(100.0, 2000.0).duration_ms, 0.0, 1e-5);
    EXPECT_NEAR(link.transfer(100.0, 3000.0).duration_ms, 100.0, 1e-9);
    // Offered after a burst passed with nothing queued: its opportunities are lost.
    EXPECT_NEAR(link.transfer(250.0, 100.0).duration_ms, 50.0, 1e-9);
}

TEST(Mahimahi, TraceLinkChainedAtEachDepartureKeepsTheBurst) {
    // The runtime model sends a frame's layers one after another, each at the link's free time
    // (start + the previous duration): four 400-byte layers queued behind the first all leave
    // in its burst. A duration floored above zero once
    // put each start past the burst's instant, so every layer waited for the next burst (a
    // stretched cellular trace then cost the model a quarter of its frames).
    auto trace = burstTrace();
    ASSERT_TRUE(trace.ok());
    // A rescaled trace (an awkward ms-per-trace-ms), so the instants are not round numbers.
    TraceLink link("bursts", shared(*trace), trace->meanBps() / 8.35, 1.0, {});
    double free_ms = 3.7;
    for (int layer = 0; layer < 4; ++layer) {
        const LinkTransfer t = link.transfer(free_ms, 400.0);
        free_ms += t.duration_ms;
        EXPECT_GE(t.duration_ms, 0.0);
    }
    EXPECT_NEAR(free_ms, 3.7 + 835.0, 1e-6);
    // Offered after the burst passed with nothing queued: the next one.
    EXPECT_NEAR(free_ms + link.transfer(free_ms + 1.0, 100.0).duration_ms + 1.0, 3.7 + 1670.0,
                1e-6);
}

TEST(Mahimahi, DeliveryQueuesAnOfferARoundingStepPastTheLastDeparture) {
    auto trace = parseMahimahiTrace("10\n10\n10\n50\n", "same-stamp");
    ASSERT_TRUE(trace.ok());
    MahimahiDelivery rule(shared(*trace), 0.0);
    const double first = rule.departureMs(0.0, 1000);
    EXPECT_DOUBLE_EQ(first, 10.0);
    // An ulp past the departure is the same instant: the stamp's other opportunities carry it.
    EXPECT_DOUBLE_EQ(rule.departureMs(std::nextafter(first, 1e9), 1500), 10.0);
    // A real gap after it is not: the stamp's last opportunity passed with nothing queued.
    EXPECT_DOUBLE_EQ(rule.departureMs(first + 0.5, 100), 50.0);
}

TEST(Mahimahi, TraceLinkLeavesWhenTheSharedRuleSays) {
    // The simulator's link is the emulator's rule (MahimahiDelivery) and nothing more: a sequence
    // of offers, in bytes and not whole packets, gets the departures the rule gives a fresh copy
    // of itself.
    auto trace = parseMahimahiTrace("0\n0\n5\n10\n", "tiny");
    ASSERT_TRUE(trace.ok());
    MahimahiDelivery rule(shared(*trace), 0.0);
    TraceLink link("tiny", shared(*trace), trace->meanBps(), 1.0, {});
    const std::vector<std::pair<double, double>> offers = {{0.0, 750},  {0.0, 750}, {0.0, 1500},
                                                           {3.0, 3000}, {12.0, 10}, {40.0, 20000}};
    for (const auto& [t, bytes] : offers) {
        const double expected = rule.departureMs(t, static_cast<int64_t>(bytes));
        EXPECT_NEAR(t + link.transfer(t, bytes).duration_ms, expected, 1e-5) << t;
    }
}

TEST(Mahimahi, SharedVerizonTraceHasItsDocumentedMeanAndRescales) {
    const std::string path = std::string(QVR_SHARED_DIR) + "/data/network/Verizon-LTE-short.down";
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << "no " << path;
    auto trace = loadMahimahiTrace(path);
    ASSERT_TRUE(trace.ok()) << trace.error();
    EXPECT_EQ(trace->stamps_ms.size(), 58655u);
    EXPECT_NEAR(trace->meanBps() / 1e6, 5.0, 0.1);
    TraceLink link("verizon", shared(*trace), 100e6, 1.0, {});
    // Over the whole (rescaled) loop the goodput is the target mean.
    const double loop_bytes = 58655 * 1500.0;
    const LinkTransfer t = link.transfer(0.0, loop_bytes);
    EXPECT_NEAR(t.goodput_bps / 1e6, 100.0, 2.0);
}

TEST(Network, ProfilesByNameAndClearErrors) {
    auto wifi = networkSpecByName("wifi");
    ASSERT_TRUE(wifi.ok());
    EXPECT_EQ(wifi->nominal_bps, 200e6);
    EXPECT_EQ(networkSpecByName("lte")->nominal_bps, 100e6);
    EXPECT_EQ(networkSpecByName("5g")->nominal_bps, 500e6);
    auto tr = networkSpecByName("trace:/x/y.down@50");
    ASSERT_TRUE(tr.ok());
    EXPECT_EQ(tr->trace_path, "/x/y.down");
    EXPECT_EQ(tr->nominal_bps, 50e6);
    EXPECT_EQ(networkSpecByName("trace:/x/y.down")->nominal_bps, 100e6);
    // "4g" is lte's other name in the link grammar; the simulator names the link lte.
    auto four = networkSpecByName("4g");
    ASSERT_TRUE(four.ok()) << four.error();
    EXPECT_EQ(four->name, "lte");
    EXPECT_EQ(four->nominal_bps, 100e6);
    for (const char* bad :
         {"wlan", "", "trace:", "trace:/a@", "trace:/a@-3", "trace:/a@x", "trace:/a@nan"}) {
        auto r = networkSpecByName(bad);
        EXPECT_FALSE(r.ok()) << bad;
    }
    // Valid link specs the paper simulator has no model for are refused with a message.
    for (const char* unmodelled : {"none", "rate:50", "wifi,delay_ms=5", "lte,loss=0.01"}) {
        auto r = networkSpecByName(unmodelled);
        ASSERT_FALSE(r.ok()) << unmodelled;
        EXPECT_NE(r.error().find("paper simulator models no"), std::string::npos) << r.error();
    }
    auto missing = networkSpecByName("trace:/nonexistent.down");
    ASSERT_TRUE(missing.ok());
    EXPECT_FALSE(makeLink(*missing, 1).ok());
}

TEST(Network, RadioEnergyPerBitFollowsTheActivePowerModel) {
    const RadioPower lte{51.97, 1288.04};
    // At 100 Mbps: α + β/R = 51.97 + 12.88 nJ/bit.
    EXPECT_NEAR(lte.energyPerBitNj(100e6), 51.97 + 12.8804, 1e-9);
    EXPECT_EQ(lte.energyPerBitNj(0.0), 0.0);
}

}  // namespace
}  // namespace qvr
