// The link grammar (core/link_spec.h): the profiles and their rates, every option and its range,
// trace specs read without and with the file, and a message for each bad spec.
#include "qvr/core/link_spec.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace qvr {
namespace {

TEST(LinkSpec, NamedProfilesAndTheirRates) {
    const std::pair<const char*, double> named[] = {
        {"none", 0.0}, {"wifi", 200e6}, {"lte", 100e6}, {"4g", 100e6}, {"5g", 500e6}};
    for (const auto& [name, bps] : named) {
        auto s = parseLinkSpec(name);
        ASSERT_TRUE(s.ok()) << name << ": " << s.error();
        EXPECT_EQ(s->rate_bps, bps) << name;
        EXPECT_EQ(s->name, name);
        EXPECT_EQ(s->options, 0);
    }
    EXPECT_EQ(parseLinkSpec("4g")->profile, "lte");
    EXPECT_FALSE(parseLinkSpec("none")->shaped());
    EXPECT_TRUE(parseLinkSpec("wifi")->shaped());
    for (const std::string& name : linkProfileNames())
        EXPECT_TRUE(parseLinkSpec(name).ok()) << name;
}

TEST(LinkSpec, RatesAndTracesWithTheirMeans) {
    auto r = parseLinkSpec("rate:42.5");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->profile, "rate");
    EXPECT_EQ(r->rate_bps, 42.5e6);
    EXPECT_EQ(parseLinkSpec("rate:0.001")->rate_bps, 1e3);
    EXPECT_EQ(parseLinkSpec("rate:1e6")->rate_bps, 1e12);
    // The grammar alone opens no file: a trace that does not exist parses.
    auto t = parseLinkSpec("trace:/no/such/dir/a@b.down@12.5,delay_ms=3");
    ASSERT_TRUE(t.ok()) << t.error();
    EXPECT_EQ(t->profile, "trace");
    EXPECT_EQ(t->trace_path, "/no/such/dir/a@b.down");  // the last '@' is the mean's
    EXPECT_EQ(t->trace_target_bps, 12.5e6);
    EXPECT_EQ(t->rate_bps, 0.0);
    EXPECT_EQ(t->trace, nullptr);
    EXPECT_EQ(t->delay_ms, 3.0);
    EXPECT_EQ(t->options, 1);
    EXPECT_EQ(parseLinkSpec("trace:x.down")->trace_target_bps, 0.0);  // as recorded
    // loadLinkSpec reads it, and names the file it cannot.
    auto missing = loadLinkSpec("trace:/no/such/trace.down");
    ASSERT_FALSE(missing.ok());
    EXPECT_NE(missing.error().find("/no/such/trace.down"), std::string::npos) << missing.error();
}

TEST(LinkSpec, LoadReadsTheTraceFile) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("qvr_link_spec_test_" + std::to_string(::getpid()) + ".down");
    std::ofstream(path) << "1\n1\n2\n4\n";
    auto s = loadLinkSpec("trace:" + path.string() + "@3");
    std::filesystem::remove(path);
    ASSERT_TRUE(s.ok()) << s.error();
    ASSERT_NE(s->trace, nullptr);
    EXPECT_EQ(s->trace->packets(), 4);
    EXPECT_EQ(s->trace->period_ms, 4);
    EXPECT_EQ(s->trace_target_bps, 3e6);
    EXPECT_TRUE(s->shaped());
    // A spec without a trace loads as it parses.
    EXPECT_EQ(loadLinkSpec("wifi")->rate_bps, 200e6);
}

TEST(LinkSpec, EveryOptionAndItsValue) {
    auto s = parseLinkSpec(
        "lte,delay_ms=15,jitter_ms=2.5,loss=0.05,queue_kb=512,seed=3,ge=0.05:0.2:0.25,"
        "reorder=0.1:7,dup=0.02,spike=500:50:30");
    ASSERT_TRUE(s.ok()) << s.error();
    EXPECT_EQ(s->options, 9);
    EXPECT_EQ(s->delay_ms, 15.0);
    EXPECT_EQ(s->jitter_ms, 2.5);
    EXPECT_EQ(s->loss, 0.05);
    EXPECT_EQ(s->queue_bytes, 512 * 1024);
    EXPECT_EQ(s->seed, 3u);
    EXPECT_EQ(s->ge_p, 0.05);
    EXPECT_EQ(s->ge_r, 0.2);
    EXPECT_EQ(s->ge_loss_bad, 0.25);
    EXPECT_EQ(s->reorder, 0.1);
    EXPECT_EQ(s->reorder_ms, 7.0);
    EXPECT_EQ(s->duplicate, 0.02);
    EXPECT_EQ(s->spike_every_ms, 500.0);
    EXPECT_EQ(s->spike_len_ms, 50.0);
    EXPECT_EQ(s->spike_extra_ms, 30.0);
    EXPECT_TRUE(s->faulty());
    // Defaults of the optional parts.
    auto d = parseLinkSpec("none,ge=0.01:0.5,reorder=0.2");
    ASSERT_TRUE(d.ok()) << d.error();
    EXPECT_EQ(d->ge_loss_bad, 1.0);
    EXPECT_EQ(d->reorder_ms, 5.0);
    EXPECT_TRUE(d->shaped());
}

TEST(LinkSpec, BadSpecsAreRefusedWithAMessageNamingThem) {
    for (const std::string bad : {"",
                                  "wlan",
                                  "WIFI",
                                  "wifi ",
                                  "4G",
                                  "rate:",
                                  "rate:0",
                                  "rate:abc",
                                  "rate:1e-300",
                                  "rate:0.0009",
                                  "rate:nan",
                                  "rate:inf",
                                  "rate:1e7",
                                  "rate:-5",
                                  "trace:",
                                  "trace:@5",
                                  "trace:/a@",
                                  "trace:/a@-3",
                                  "trace:/a@x",
                                  "trace:/a@nan",
                                  "trace:/a@0",
                                  "lte,",
                                  "lte,loss=1",
                                  "lte,loss=-0.1",
                                  "lte,loss=nan",
                                  "lte,delay_ms=x",
                                  "lte,delay_ms=1e5",
                                  "lte,delay_ms",
                                  "lte,foo=1",
                                  "lte,queue_kb=0",
                                  "lte,queue_kb=-1",
                                  "lte,seed=-1",
                                  "lte,seed=1.5",
                                  "lte,ge=0.1",
                                  "lte,ge=1:0.5",
                                  "lte,ge=0.1:0",
                                  "lte,ge=0.1:0.5:0",
                                  "lte,ge=0.1:0.5:1:1",
                                  "lte,reorder=1",
                                  "lte,reorder=0.1:0",
                                  "lte,dup=1",
                                  "lte,spike=10:20:5",
                                  "lte,spike=10:5",
                                  "lte,spike=10:5:0",
                                  "lte,jitter_ms=inf"}) {
        auto s = parseLinkSpec(bad);
        ASSERT_FALSE(s.ok()) << "'" << bad << "' was accepted";
        EXPECT_NE(s.error().find("link '" + bad + "'"), std::string::npos) << s.error();
    }
}

}  // namespace
}  // namespace qvr
