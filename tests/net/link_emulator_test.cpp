// Link emulator under a fake clock: serialization at the configured rate in closed form, delay
// and jitter bounds, loss rate, drop-tail queue, and Mahimahi traces at their README means.
#include "qvr/net/link_emulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "qvr/core/clock.h"
#include "qvr/core/mahimahi.h"

namespace qvr::net {
namespace {

const std::string kTraceDir = std::string(QVR_SHARED_DIR) + "/data/network/";

std::vector<uint8_t> packet(size_t n) {
    return std::vector<uint8_t>(n, 0xAB);
}

// Delivers everything, stepping a fake clock to each next delivery; returns the time the last
// packet arrived.
int64_t drainAll(LinkEmulator& link, FakeClock& clock, int64_t& packets, int64_t& bytes) {
    std::vector<std::vector<uint8_t>> out;
    int64_t last_ns = clock.nowNs();
    while (auto next = link.nextDeliveryNs()) {
        clock.setNs(std::max(clock.nowNs(), *next));
        out.clear();
        link.deliver(clock.nowNs(), out);
        for (const auto& p : out) {
            ++packets;
            bytes += static_cast<int64_t>(p.size());
        }
        last_ns = clock.nowNs();
    }
    return last_ns;
}

TEST(NetLinkEmulator, SerializesAtTheConfiguredRate) {
    // N bytes at R bit/s leave the bottleneck after N·8/R; with a fixed delay d, arrive d later.
    for (double mbps : {100.0, 200.0, 500.0}) {
        LinkSpec c;
        c.rate_bps = mbps * 1e6;
        c.delay_ms = 3.0;
        c.queue_bytes = 64 << 20;
        LinkEmulator link(c);
        FakeClock clock;
        const int64_t n_packets = 1000, size = 1232;
        for (int i = 0; i < n_packets; ++i) {
            ASSERT_TRUE(link.send(packet(size), clock.nowNs()));
        }
        int64_t packets = 0, bytes = 0;
        const int64_t last_ns = drainAll(link, clock, packets, bytes);
        const double expected_ns = n_packets * size * 8.0 / c.rate_bps * 1e9 + 3e6;
        EXPECT_EQ(packets, n_packets);
        EXPECT_EQ(bytes, n_packets * size);
        EXPECT_NEAR(static_cast<double>(last_ns), expected_ns, 1.0) << mbps;
    }
}

TEST(NetLinkEmulator, PacedSenderSeesOnlyTheDelay) {
    LinkSpec c;
    c.rate_bps = 100e6;
    c.delay_ms = 10.0;
    LinkEmulator link(c);
    FakeClock clock;
    // One 1250-byte packet every 1 ms is 10 Mbit/s: no queue forms, each takes 0.1 ms + 10 ms.
    std::vector<std::vector<uint8_t>> out;
    std::vector<int64_t> arrivals;
    for (int i = 0; i < 50; ++i) {
        ASSERT_TRUE(link.send(packet(1250), clock.nowNs()));
        // Step through the next millisecond at every delivery time inside it.
        const int64_t end_ns = clock.nowNs() + 1'000'000;
        while (link.nextDeliveryNs() && *link.nextDeliveryNs() < end_ns) {
            clock.setNs(*link.nextDeliveryNs());
            out.clear();
            link.deliver(clock.nowNs(), out);
            arrivals.insert(arrivals.end(), out.size(), clock.nowNs());
        }
        clock.setNs(end_ns);
    }
    ASSERT_GE(arrivals.size(), 40u);
    for (size_t i = 0; i < arrivals.size(); ++i) {
        EXPECT_EQ(arrivals[i], static_cast<int64_t>(i) * 1'000'000 + 100'000 + 10'000'000) << i;
    }
}

TEST(NetLinkEmulator, JitterStaysInBoundsAndKeepsOrder) {
    LinkSpec c;
    c.delay_ms = 20.0;
    c.jitter_ms = 5.0;
    c.seed = 7;
    LinkEmulator link(c);
    FakeClock clock;
    int64_t prev = 0;
    double sum_ms = 0;
    int64_t early = 0, late = 0;
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
        std::vector<uint8_t> p = packet(100);
        p[0] = static_cast<uint8_t>(i);
        ASSERT_TRUE(link.send(std::move(p), clock.nowNs()));
        const int64_t d = *link.nextDeliveryNs() - clock.nowNs();
        // Order is kept, so a packet may wait for the one before it: only the lower bound and
        // the upper bound of the sampled delay hold for every packet.
        EXPECT_GE(d, 15'000'000 - 1);
        EXPECT_GE(*link.nextDeliveryNs(), prev);
        prev = *link.nextDeliveryNs();
        std::vector<std::vector<uint8_t>> out;
        clock.advanceNs(30'000'000);  // past any delay, so the next packet is alone in the line
        link.deliver(clock.nowNs(), out);
        ASSERT_EQ(out.size(), 1u);
        EXPECT_EQ(out[0][0], static_cast<uint8_t>(i));
        EXPECT_LE(d, 25'000'000 + 1);
        sum_ms += static_cast<double>(d) / 1e6;
        early += d < 20'000'000;
        late += d > 20'000'000;
    }
    EXPECT_NEAR(sum_ms / n, 20.0, 0.3);  // uniform ±5 ms: σ of the mean ≈ 0.065 ms
    EXPECT_GT(early, n / 3);
    EXPECT_GT(late, n / 3);
}

TEST(NetLinkEmulator, LossMatchesItsProbabilityAndIsDeterministic) {
    LinkSpec c;
    c.loss = 0.05;
    c.seed = 11;
    auto run = [&] {
        LinkEmulator link(c);
        std::vector<bool> kept;
        for (int i = 0; i < 20000; ++i) {
            kept.push_back(link.send(packet(10), 0));
        }
        return std::make_pair(kept, link.stats());
    };
    const auto [a, stats] = run();
    const auto [b, stats_b] = run();
    EXPECT_EQ(a, b);  // the same seed gives the same losses
    const double rate = static_cast<double>(stats.dropped_loss) / 20000.0;
    EXPECT_NEAR(rate, 0.05, 0.006);  // 4σ of a binomial(20000, 0.05)
    EXPECT_EQ(stats.packets_in, 20000u);
}

TEST(NetLinkEmulator, DropTailQueueBoundsTheBacklog) {
    LinkSpec c;
    c.rate_bps = 8e6;  // 1 byte per µs
    c.queue_bytes = 10'000;
    LinkEmulator link(c);
    int accepted = 0;
    for (int i = 0; i < 20; ++i) {
        accepted += link.send(packet(1000), 0) ? 1 : 0;
    }
    EXPECT_EQ(accepted, 10);
    EXPECT_EQ(link.stats().dropped_queue, 10u);
    EXPECT_EQ(link.queuedBytes(0), 10'000);
    // After 5 ms half the backlog has left; room for five more.
    EXPECT_EQ(link.queuedBytes(5'000'000), 5'000);
    for (int i = 0; i < 6; ++i) {
        accepted += link.send(packet(1000), 5'000'000) ? 1 : 0;
    }
    EXPECT_EQ(accepted, 15);
}

TEST(NetLinkEmulator, DelayLineIsBoundedWithoutARateLimit) {
    LinkSpec c;
    c.delay_ms = 1000.0;  // no rate: nothing waits in the queue, everything in the delay line
    c.max_in_flight_bytes = 100'000;
    LinkEmulator link(c);
    int accepted = 0;
    for (int i = 0; i < 200; ++i) {
        accepted += link.send(packet(1000), 0) ? 1 : 0;
    }
    EXPECT_EQ(accepted, 100);
    std::vector<std::vector<uint8_t>> out;
    link.deliver(1'000'000'000, out);
    EXPECT_EQ(out.size(), 100u);
    EXPECT_TRUE(link.send(packet(1000), 1'000'000'000));  // room again once delivered
}

TEST(NetLinkEmulator, ParsesProfilesAndOptions) {
    auto wifi = parseLinkSpec("wifi");
    ASSERT_TRUE(wifi) << wifi.error();
    EXPECT_EQ(wifi->rate_bps, 200e6);
    EXPECT_EQ(parseLinkSpec("lte")->rate_bps, 100e6);
    EXPECT_EQ(parseLinkSpec("5g")->rate_bps, 500e6);
    EXPECT_FALSE(parseLinkSpec("none")->shaped());
    auto opts = parseLinkSpec("lte,delay_ms=15,jitter_ms=2.5,loss=0.05,queue_kb=512,seed=3");
    ASSERT_TRUE(opts) << opts.error();
    EXPECT_EQ(opts->delay_ms, 15.0);
    EXPECT_EQ(opts->jitter_ms, 2.5);
    EXPECT_EQ(opts->loss, 0.05);
    EXPECT_EQ(opts->queue_bytes, 512 * 1024);
    EXPECT_EQ(opts->seed, 3u);
    EXPECT_EQ(parseLinkSpec("rate:42.5")->rate_bps, 42.5e6);
    for (const char* bad :
         {"wlan", "lte,loss=1", "lte,loss=-0.1", "lte,delay_ms=x", "lte,foo=1", "lte,delay_ms",
          "rate:0", "rate:abc", "trace:/nonexistent.down", "lte,queue_kb=0", "rate:1e-300",
          "rate:0.0009", "rate:nan", "rate:inf", "rate:1e7"}) {
        EXPECT_FALSE(loadLinkSpec(bad)) << bad;
    }
}

TEST(NetLinkEmulator, UnrepresentableRatesAreRefusedNotOverflowed) {
    // The slowest rate the parser takes still delivers, late but at a representable time.
    auto slow = parseLinkSpec("rate:0.001");
    ASSERT_TRUE(slow) << slow.error();
    {
        LinkEmulator link(*slow);
        FakeClock clock;
        ASSERT_TRUE(link.send(packet(1232), clock.nowNs()));
        ASSERT_TRUE(link.nextDeliveryNs().has_value());
        EXPECT_NEAR(static_cast<double>(*link.nextDeliveryNs()), 1232 * 8.0 / 1e3 * 1e9, 1.0);
    }
    // A config built by hand with a rate near zero (which the parser refuses): the packet could
    // never leave, so it is a counted queue drop rather than an instant delivery of llround's
    // overflow that stays in the queue for ever.
    LinkSpec c;
    c.rate_bps = 1e-300;
    LinkEmulator link(c);
    FakeClock clock;
    EXPECT_FALSE(link.send(packet(1232), clock.nowNs()));
    EXPECT_EQ(link.stats().dropped_queue, 1u);
    EXPECT_FALSE(link.nextDeliveryNs().has_value());
    std::vector<std::vector<uint8_t>> out;
    link.deliver(std::numeric_limits<int64_t>::max(), out);
    EXPECT_TRUE(out.empty());
}

struct ReadmeRow {
    const char* file;
    int64_t packets;
    double mean_mbps;
};

TEST(NetMahimahi, TracesMatchTheReadmeTable) {
    for (const ReadmeRow& row : {ReadmeRow{"Verizon-LTE-short.down", 58655, 5.0},
                                 ReadmeRow{"TMobile-LTE-short.down", 194846, 16.7},
                                 ReadmeRow{"ATT-LTE-driving-2016.down", 45604, 4.6}}) {
        auto trace = loadMahimahiTrace(kTraceDir + row.file);
        ASSERT_TRUE(trace) << trace.error();
        EXPECT_EQ(trace->packets(), row.packets) << row.file;
        EXPECT_NEAR(trace->meanBps() / 1e6, row.mean_mbps, 0.05) << row.file;
    }
}

// A saturating sender over one loop of the trace measures the trace's mean; rescaled, the
// target mean. The sender keeps 1 MB queued (more than any burst of opportunities drains in
// a 1 ms step), so the link never idles.
double measuredMeanBps(LinkSpec c, double loop_ns) {
    c.queue_bytes = 2 << 20;
    LinkEmulator link(c);
    FakeClock clock;
    int64_t delivered = 0;
    std::vector<std::vector<uint8_t>> out;
    while (clock.nowNs() < static_cast<int64_t>(loop_ns)) {
        while (link.queuedBytes(clock.nowNs()) < 1024 * 1024) {
            link.send(packet(1500), clock.nowNs());
        }
        clock.advanceNs(1'000'000);
        out.clear();
        link.deliver(clock.nowNs(), out);
        for (const auto& p : out) {
            delivered += static_cast<int64_t>(p.size());
        }
    }
    return static_cast<double>(delivered) * 8.0 / (loop_ns / 1e9);
}

TEST(NetMahimahi, TraceLinkDeliversTheMeanAndRescales) {
    auto trace = loadMahimahiTrace(kTraceDir + "TMobile-LTE-short.down");
    ASSERT_TRUE(trace) << trace.error();
    LinkSpec c;
    c.trace = std::make_shared<const MahimahiTrace>(std::move(trace).value());
    const double mean = c.trace->meanBps();
    const double period_ns = static_cast<double>(c.trace->period_ms) * 1e6;
    EXPECT_NEAR(measuredMeanBps(c, period_ns) / mean, 1.0, 0.01);

    c.trace_target_bps = 100e6;  // the paper's LTE: every stamp divided by 100 / 16.7
    const LinkEmulator scaled(c);
    EXPECT_NEAR(scaled.traceNsPerMs(), 1e6 * mean / 100e6, 1e-6);
    EXPECT_NEAR(measuredMeanBps(c, period_ns * mean / 100e6) / 100e6, 1.0, 0.01);
}

TEST(NetMahimahi, OpportunitiesFollowTheStampsAndLoop) {
    // Stamps 0, 0, 5, 10 ms: two packets at 0, one at 5, one at 10, then the loop repeats
    // shifted by 10 ms (Mahimahi's rule: the last stamp is the period).
    auto trace = parseMahimahiTrace("0\n0\n5\n10\n", "tiny");
    ASSERT_TRUE(trace) << trace.error();
    LinkSpec c;
    c.trace = std::make_shared<const MahimahiTrace>(std::move(trace).value());
    LinkEmulator link(c);
    std::vector<int64_t> times;
    for (int i = 0; i < 8; ++i) {
        ASSERT_TRUE(link.send(packet(1500), 0));
    }
    std::vector<std::vector<uint8_t>> out;
    for (int64_t t = 0; t <= 30'000'000; t += 1'000'000) {
        out.clear();
        link.deliver(t, out);
        for (size_t k = 0; k < out.size(); ++k) {
            times.push_back(t / 1'000'000);
        }
    }
    EXPECT_EQ(times, (std::vector<int64_t>{0, 0, 5, 10, 10, 10, 15, 20}));
    // Two 750-byte packets share one opportunity.
    LinkEmulator half(c);
    ASSERT_TRUE(half.send(packet(750), 1'000'000));
    ASSERT_TRUE(half.send(packet(750), 1'000'000));
    out.clear();
    half.deliver(5'000'000, out);
    EXPECT_EQ(out.size(), 2u);
}

TEST(NetMahimahi, MalformedFilesAreRejectedWithTheLine) {
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"", "no delivery"},
        {"\n\n", "no delivery"},
        {"0\n0\n", "last timestamp"},
        {"5\n3\n", ":2: timestamp 3 ms goes back"},
        {"1\n-2\n", ":2: expected"},
        {"1\n2 \n", ":2: expected"},
        {"1\nabc\n", ":2: expected"},
        {"1\n12345678901\n", "too long"},
        {"1\n2000000000\n", "exceeds"},
        {std::string("1\n2\0\n", 5), "expected"},
    };
    for (const auto& [text, message] : bad) {
        auto t = parseMahimahiTrace(text, "bad.down");
        ASSERT_FALSE(t) << text;
        EXPECT_NE(t.error().find(message), std::string::npos) << t.error();
    }
    auto crlf = parseMahimahiTrace("1\r\n2\r\n\r\n4\n", "crlf.down");
    ASSERT_TRUE(crlf) << crlf.error();
    EXPECT_EQ(crlf->packets(), 3);
    EXPECT_FALSE(loadMahimahiTrace("/nonexistent/trace.down"));
}

}  // namespace
}  // namespace qvr::net

namespace qvr::net {
namespace {

// Sends n 1000-byte packets 1 ms apart through a link; returns the packets as delivered, each
// tagged with its send index (first 4 bytes).
struct Delivered {
    std::vector<uint32_t> order;
    std::vector<int64_t> at_ns;
};
Delivered sendNumbered(LinkEmulator& link, uint32_t n, std::vector<bool>* accepted = nullptr) {
    FakeClock clock;
    Delivered d;
    std::vector<std::vector<uint8_t>> out;
    auto take = [&] {
        out.clear();
        link.deliver(clock.nowNs(), out);
        for (const auto& p : out) {
            uint32_t i = 0;
            std::memcpy(&i, p.data(), 4);
            d.order.push_back(i);
            d.at_ns.push_back(clock.nowNs());
        }
    };
    for (uint32_t i = 0; i < n; ++i) {
        std::vector<uint8_t> p(1000, 0);
        std::memcpy(p.data(), &i, 4);
        const bool ok = link.send(std::move(p), clock.nowNs());
        if (accepted)
            accepted->push_back(ok);
        take();
        clock.setNs(clock.nowNs() + 1'000'000);
    }
    while (auto next = link.nextDeliveryNs()) {
        clock.setNs(std::max(clock.nowNs(), *next));
        take();
    }
    return d;
}

TEST(NetLinkFaults, GilbertElliottLosesInBurstsAtItsLongRunRate) {
    LinkSpec c = parseLinkSpec("none,ge=0.01:0.25,seed=4").value();
    LinkEmulator link(c);
    std::vector<bool> ok;
    sendNumbered(link, 200'000, &ok);
    int64_t lost = 0, bursts = 0;
    for (size_t i = 0; i < ok.size(); ++i) {
        lost += !ok[i];
        bursts += !ok[i] && (i == 0 || ok[i - 1]);
    }
    const double rate = double(lost) / double(ok.size());
    EXPECT_NEAR(rate, 0.01 / 0.26, 0.004);                 // p / (p + r) = 3.85%
    EXPECT_NEAR(double(lost) / double(bursts), 4.0, 0.3);  // mean burst 1 / r
    EXPECT_EQ(link.stats().dropped_burst, uint64_t(lost));
    EXPECT_EQ(link.stats().dropped_loss, 0u);
}

TEST(NetLinkFaults, ReorderedPacketsAreOvertakenAndOthersKeepOrder) {
    LinkEmulator link(parseLinkSpec("wifi,reorder=0.05:5,seed=2").value());
    const Delivered d = sendNumbered(link, 20'000);
    ASSERT_EQ(d.order.size(), 20'000u);  // nothing lost, each once
    int64_t late = 0;
    uint32_t highest = 0;
    for (size_t k = 0; k < d.order.size(); ++k) {
        late += k > 0 && d.order[k] < highest;
        highest = std::max(highest, d.order[k]);
    }
    // Held 5 ms with packets sent every 1 ms: each held packet arrives after ~5 later ones.
    EXPECT_NEAR(double(late) / 20'000.0, 0.05, 0.01);
    EXPECT_EQ(uint64_t(late), link.stats().reordered);
    std::vector<uint32_t> sorted = d.order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
}

TEST(NetLinkFaults, DuplicatesArriveRightAfterTheirOriginal) {
    LinkEmulator link(parseLinkSpec("wifi,dup=0.1,seed=3").value());
    const Delivered d = sendNumbered(link, 10'000);
    const uint64_t dups = link.stats().duplicated;
    EXPECT_NEAR(double(dups) / 10'000.0, 0.1, 0.015);
    ASSERT_EQ(d.order.size(), 10'000u + dups);
    uint64_t adjacent = 0;
    for (size_t k = 1; k < d.order.size(); ++k)
        adjacent += d.order[k] == d.order[k - 1];
    EXPECT_EQ(adjacent, dups);
}

TEST(NetLinkFaults, SpikesDelayExactlyThePacketsSentDuringThem) {
    // No rate, no delay: a packet arrives when sent, or 80 ms later if sent in the last 100 ms of
    // each second (order kept, so the ones right after a spike wait for it to drain).
    LinkEmulator link(parseLinkSpec("none,spike=1000:100:80").value());
    const Delivered d = sendNumbered(link, 3000);
    ASSERT_EQ(d.order.size(), 3000u);
    for (size_t k = 0; k < d.order.size(); ++k) {
        const uint32_t i = d.order[k];
        ASSERT_EQ(i, k);
        const int64_t sent_ns = int64_t(i) * 1'000'000;
        const bool in_spike = i % 1000 >= 900;
        const int64_t spike_end_ns = (int64_t(i) / 1000) * 1'000'000'000 + 999'000'000 + 80'000'000;
        if (in_spike)
            EXPECT_EQ(d.at_ns[k], sent_ns + 80'000'000) << i;
        else if (i % 1000 < 80 && i >= 1000)
            EXPECT_EQ(d.at_ns[k], std::max(sent_ns, spike_end_ns - 1'000'000'000)) << i;
        else
            EXPECT_EQ(d.at_ns[k], sent_ns) << i;
    }
    EXPECT_EQ(link.stats().spiked, 300u);
}

TEST(NetLinkFaults, BurstLossIsIndependentOfRandomLossAndOfTheOtherFaults) {
    // The chain steps on every packet: with loss= on too, every packet the bursts took alone
    // is still lost, and random loss takes its share of the rest.
    std::vector<bool> ge_only, both, ge_dup;
    LinkEmulator a(parseLinkSpec("wifi,ge=0.01:0.25,seed=6").value());
    LinkEmulator b(parseLinkSpec("wifi,ge=0.01:0.25,loss=0.1,seed=6").value());
    LinkEmulator c(parseLinkSpec("wifi,ge=0.01:0.25,dup=0.3,reorder=0.2,seed=6").value());
    sendNumbered(a, 100'000, &ge_only);
    sendNumbered(b, 100'000, &both);
    sendNumbered(c, 100'000, &ge_dup);
    EXPECT_EQ(ge_only, ge_dup);  // duplication and reordering draw from streams of their own
    int64_t burst = 0, extra = 0, survivors = 0;
    for (size_t i = 0; i < ge_only.size(); ++i) {
        if (!ge_only[i]) {
            ++burst;
            EXPECT_FALSE(both[i]) << i;
        } else {
            ++survivors;
            extra += !both[i];
        }
    }
    EXPECT_NEAR(double(extra) / double(survivors), 0.1, 0.005);
    // A packet both would take is counted as random loss.
    EXPECT_EQ(b.stats().dropped_loss + b.stats().dropped_burst, uint64_t(burst + extra));
    EXPECT_LT(b.stats().dropped_burst, uint64_t(burst));
}

TEST(NetLinkFaults, PartialLossInTheBadStateScalesTheLongRunRate) {
    LinkEmulator link(parseLinkSpec("none,ge=0.02:0.1:0.5,seed=8").value());
    std::vector<bool> ok;
    sendNumbered(link, 200'000, &ok);
    const auto lost = std::count(ok.begin(), ok.end(), false);
    // 0.5 · p / (p + r) = 8.33%
    EXPECT_NEAR(double(lost) / double(ok.size()), 0.5 * 0.02 / 0.12, 0.006);
    EXPECT_EQ(link.stats().dropped_burst, uint64_t(lost));
}

TEST(NetLinkFaults, HeldPacketsLeaveAtTheirOwnTimeEvenWhenSpikesMakeThemNonMonotonic) {
    // Every packet held 5 ms (P just under 1; this seed holds all 3000): one sent in the last
    // 100 ms of a second is due 85 ms after it was sent, the others 5 ms; so packets sent just
    // after a spike overtake the held spike packets, and each copy follows its original.
    LinkEmulator link(parseLinkSpec("none,spike=1000:100:80,reorder=0.999999:5,dup=0.3").value());
    const Delivered d = sendNumbered(link, 3000);
    ASSERT_EQ(link.stats().reordered, 3000u);
    ASSERT_EQ(d.order.size(), 3000u + link.stats().duplicated);
    std::vector<int64_t> due_ns(3000);
    for (uint32_t i = 0; i < 3000; ++i)
        due_ns[i] = int64_t(i) * 1'000'000 + (i % 1000 >= 900 ? 85'000'000 : 5'000'000);
    uint64_t copies = 0;
    for (size_t k = 0; k < d.order.size(); ++k) {
        EXPECT_EQ(d.at_ns[k], due_ns[d.order[k]]) << "packet " << d.order[k];
        if (k > 0) {
            copies += d.order[k] == d.order[k - 1];
            EXPECT_LE(due_ns[d.order[k - 1]], due_ns[d.order[k]]) << k;
        }
    }
    EXPECT_EQ(copies, link.stats().duplicated);
    EXPECT_GT(copies, 800u);
}

TEST(NetLinkFaults, WithoutFaultsTheLinkIsUnchangedAndBadSpecsAreRefused) {
    // The fault options draw from their own stream: random loss picks the same packets.
    std::vector<bool> a, b;
    LinkEmulator plain(parseLinkSpec("wifi,loss=0.1,seed=9").value());
    LinkEmulator with(parseLinkSpec("wifi,loss=0.1,seed=9,dup=0.2,reorder=0.1").value());
    sendNumbered(plain, 5000, &a);
    sendNumbered(with, 5000, &b);
    EXPECT_EQ(a, b);
    for (const char* bad : {"wifi,ge=junk",
                            "wifi,ge=0.1",
                            "wifi,ge=0.1:0",
                            "wifi,ge=1:0.5",
                            "wifi,ge=0.1:0.2:3",
                            "wifi,ge=nan:0.5",
                            "wifi,ge=0.1:0.2:0",
                            "wifi,ge=0.1:0.2:0.5:1",
                            "wifi,ge=-0.1:0.5",
                            "wifi,ge=0.1:",
                            "wifi,ge=:0.5",
                            "wifi,ge=",
                            "wifi,ge=0.1:inf",
                            "wifi,reorder=",
                            "wifi,reorder=0.1:",
                            "wifi,reorder=0.1:nan",
                            "wifi,reorder=0.1:-5",
                            "wifi,dup=-0.1",
                            "wifi,dup=nan",
                            "wifi,dup=",
                            "wifi,spike=1000:100:-80",
                            "wifi,spike=1000:-1:80",
                            "wifi,spike=nan:100:80",
                            "wifi,spike=1000::80",
                            "wifi,spike=",
                            "wifi,reorder=1",
                            "wifi,reorder=0.1:0",
                            "wifi,reorder=0.1:20000",
                            "wifi,reorder=-0.1",
                            "wifi,dup=1",
                            "wifi,dup=x",
                            "wifi,spike=1000:100",
                            "wifi,spike=100:200:5",
                            "wifi,spike=1000:100:0",
                            "wifi,spike=1000:100:99999",
                            "wifi,spike=0:0:5",
                            "wifi,spike=1000:100:80:1"}) {
        auto c = parseLinkSpec(bad);
        EXPECT_FALSE(c.ok()) << bad;
        if (!c.ok()) {
            EXPECT_NE(c.error().find("must be"), std::string::npos) << c.error();
        }
    }
    // The defaults and the optional parts.
    const LinkSpec g = parseLinkSpec("wifi,ge=0.05:0.2,reorder=0.1,dup=0.02").value();
    EXPECT_EQ(g.ge_p, 0.05);
    EXPECT_EQ(g.ge_r, 0.2);
    EXPECT_EQ(g.ge_loss_bad, 1.0);
    EXPECT_EQ(g.reorder, 0.1);
    EXPECT_EQ(g.reorder_ms, 5.0);
    EXPECT_EQ(g.duplicate, 0.02);
    EXPECT_TRUE(g.faulty());
    const LinkSpec h = parseLinkSpec("none,ge=0.05:0.2:0.25,spike=500:50:30").value();
    EXPECT_EQ(h.ge_loss_bad, 0.25);
    EXPECT_EQ(h.spike_every_ms, 500.0);
    EXPECT_EQ(h.spike_len_ms, 50.0);
    EXPECT_EQ(h.spike_extra_ms, 30.0);
    EXPECT_FALSE(parseLinkSpec("none,ge=0:0.5,reorder=0,dup=0").value().faulty());  // all off
}

}  // namespace
}  // namespace qvr::net
