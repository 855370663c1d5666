// The gaze model (paper §3.1: the fovea follows the gaze; §7: 120 Hz eye trackers): seeded,
// sampled at the tracker rate, saccades on the main sequence as measured from its own samples,
// bounded; and gaze CSV both ways.
#include "qvr/trace/gaze_model.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace qvr {
namespace {

using ::testing::HasSubstr;

GazeTrace generate(uint64_t seed, int samples, const GazeModelConfig& c = {}) {
    auto t = generateGaze(c, seed, samples);
    QVR_CHECK_MSG(t.ok(), "generateGaze failed");
    return std::move(t).value();
}

TEST(GazeModel, SameSeedSameTraceOtherSeedOtherTrace) {
    const GazeTrace a = generate(42, 2000);
    const GazeTrace b = generate(42, 2000);
    const GazeTrace c = generate(43, 2000);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    int differ = 0;
    for (size_t i = 0; i < a.samples.size(); ++i) {
        EXPECT_EQ(a.samples[i].gaze.x_deg, b.samples[i].gaze.x_deg);
        EXPECT_EQ(a.samples[i].gaze.y_deg, b.samples[i].gaze.y_deg);
        differ += a.samples[i].gaze.x_deg != c.samples[i].gaze.x_deg ? 1 : 0;
    }
    EXPECT_GT(differ, 1900);
}

TEST(GazeModel, SamplesAtTheTrackerRate) {
    const GazeTrace t = generate(1, 1200);
    ASSERT_EQ(t.samples.size(), 1200u);
    for (size_t i = 0; i < t.samples.size(); ++i)
        EXPECT_NEAR(t.samples[i].t_ms, static_cast<double>(i) * 1000.0 / 120.0, 1e-9);
    GazeModelConfig c;
    c.sample_rate_hz = 250.0;
    const GazeTrace fast = generate(1, 10, c);
    EXPECT_NEAR(fast.samples[9].t_ms, 36.0, 1e-9);
}

TEST(GazeModel, StaysWithinItsBounds) {
    GazeModelConfig c;
    c.pursuit_probability = 0.3;
    c.saccade_median_deg = 15.0;  // push against the bounds
    for (uint64_t seed = 0; seed < 20; ++seed) {
        const GazeTrace t = generate(seed, 3000, c);
        for (const auto& s : t.samples) {
            const double u = s.gaze.x_deg / c.bound_x_deg;
            const double v = s.gaze.y_deg / c.bound_y_deg;
            ASSERT_LE(u * u + v * v, 1.0 + 1e-9) << "seed " << seed << " t " << s.t_ms;
        }
    }
}

// Saccades found in the samples themselves (velocity threshold, as eye-tracking software
// does): {amplitude, duration} pairs.
std::vector<std::pair<double, double>> detectSaccades(const GazeTrace& t, double step_ms) {
    std::vector<std::pair<double, double>> found;
    const double threshold_deg_s = 40.0;
    size_t i = 1;
    while (i < t.samples.size()) {
        auto speed = [&](size_t k) {
            const auto& a = t.samples[k - 1].gaze;
            const auto& b = t.samples[k].gaze;
            return std::hypot(b.x_deg - a.x_deg, b.y_deg - a.y_deg) / (step_ms / 1000.0);
        };
        if (speed(i) <= threshold_deg_s) {
            ++i;
            continue;
        }
        const size_t start = i - 1;
        while (i < t.samples.size() && speed(i) > threshold_deg_s)
            ++i;
        const size_t end = std::min(i, t.samples.size() - 1);
        const auto& a = t.samples[start].gaze;
        const auto& b = t.samples[end].gaze;
        found.push_back({std::hypot(b.x_deg - a.x_deg, b.y_deg - a.y_deg),
                         static_cast<double>(i - 1 - start) * step_ms});
    }
    return found;
}

TEST(GazeModel, SaccadesFollowTheMainSequenceInTheSamples) {
    const GazeModelConfig c;
    std::vector<std::pair<double, double>> all;
    for (uint64_t seed = 0; seed < 10; ++seed) {
        const GazeTrace t = generate(seed, 6000, c);
        // Ground truth first: each saccade event is on the main sequence.
        for (const auto& e : t.events) {
            if (e.kind != GazeEventKind::kSaccade)
                continue;
            EXPECT_NEAR(e.duration_ms, 2.2 * e.amplitude_deg + 21.0, 1e-9);
            EXPECT_LE(e.peak_velocity_deg_s, 500.0 + 1e-9);
        }
        const auto found = detectSaccades(t, 1000.0 / 120.0);
        all.insert(all.end(), found.begin(), found.end());
    }
    // Least-squares line duration = slope·A + intercept through the detected saccades of 2°+.
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [a, d] : all) {
        if (a < 2.0)
            continue;
        n += 1;
        sx += a;
        sy += d;
        sxx += a * a;
        sxy += a * d;
    }
    ASSERT_GT(n, 200);
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    const double intercept = (sy - slope * sx) / n;
    // 120 Hz quantises durations to 8.3 ms; the fit over hundreds of saccades still recovers
    // the main sequence to within a fraction of that.
    EXPECT_NEAR(slope, 2.2, 0.5) << "intercept " << intercept;
    EXPECT_NEAR(intercept, 21.0, 8.0) << "slope " << slope;
}

TEST(GazeModel, PeakVelocitySaturatesNear500DegPerSecond) {
    const GazeModelConfig c;
    EXPECT_NEAR(saccadePeakVelocityDegS(c, 40.0), 500.0, 2.0);
    EXPECT_LT(saccadePeakVelocityDegS(c, 2.0), 150.0);
    // The velocity profile reaches the main sequence's peak and covers the amplitude.
    for (double a : {1.0, 5.0, 12.0, 30.0}) {
        const double d_s = saccadeDurationMs(c, a) / 1000.0;
        double peak = 0.0;
        const int steps = 20000;
        for (int k = 1; k <= steps; ++k) {
            const double p0 = saccadeProgress(c, a, (k - 1.0) / steps);
            const double p1 = saccadeProgress(c, a, static_cast<double>(k) / steps);
            ASSERT_GE(p1, p0);
            peak = std::max(peak, (p1 - p0) * a / (d_s / steps));
        }
        EXPECT_NEAR(saccadeProgress(c, a, 0.0), 0.0, 1e-12);
        EXPECT_NEAR(saccadeProgress(c, a, 1.0), 1.0, 1e-12);
        EXPECT_NEAR(peak, saccadePeakVelocityDegS(c, a), 0.02 * saccadePeakVelocityDegS(c, a)) << a;
    }
    // In the sampled trace no sample-to-sample speed exceeds the saturation velocity.
    const GazeTrace t = generate(5, 12000);
    for (size_t i = 1; i < t.samples.size(); ++i) {
        const auto& a = t.samples[i - 1].gaze;
        const auto& b = t.samples[i].gaze;
        ASSERT_LE(std::hypot(b.x_deg - a.x_deg, b.y_deg - a.y_deg) * 120.0, 500.0);
    }
}

TEST(GazeModel, FixationsLastAboutAQuarterSecond) {
    const GazeTrace t = generate(9, 60000);
    std::vector<double> d;
    for (const auto& e : t.events) {
        if (e.kind == GazeEventKind::kFixation)
            d.push_back(e.duration_ms);
    }
    ASSERT_GT(d.size(), 500u);
    std::nth_element(d.begin(), d.begin() + static_cast<ptrdiff_t>(d.size() / 2), d.end());
    EXPECT_NEAR(d[d.size() / 2], 250.0, 25.0);
}

TEST(GazeModel, PursuitMovesSlowlyAndSmoothly) {
    GazeModelConfig c;
    c.pursuit_probability = 1.0;
    const GazeTrace t = generate(3, 6000, c);
    int pursuits = 0;
    for (const auto& e : t.events) {
        if (e.kind == GazeEventKind::kPursuit) {
            ++pursuits;
            EXPECT_LE(e.peak_velocity_deg_s, c.pursuit_max_deg_s + 1e-9);
        }
        EXPECT_NE(e.kind, GazeEventKind::kFixation);
    }
    EXPECT_GT(pursuits, 50);
}

TEST(GazeModel, TrackerNoiseIsSeededToo) {
    GazeModelConfig c;
    c.tracker_noise_deg = 0.5;
    const GazeTrace a = generate(8, 500, c);
    const GazeTrace b = generate(8, 500, c);
    const GazeTrace clean = generate(8, 500);
    double diff = 0;
    for (size_t i = 0; i < a.samples.size(); ++i) {
        EXPECT_EQ(a.samples[i].gaze.x_deg, b.samples[i].gaze.x_deg);
        diff += std::fabs(a.samples[i].gaze.x_deg - clean.samples[i].gaze.x_deg);
    }
    EXPECT_NEAR(diff / 500.0, 0.5 * std::sqrt(2.0 / 3.14159265), 0.08);  // mean |N(0, σ)|
}

TEST(GazeModel, RejectsBadConfigs) {
    GazeModelConfig c;
    c.sample_rate_hz = 0;
    EXPECT_FALSE(generateGaze(c, 1, 10).ok());
    c = {};
    c.bound_x_deg = 200;
    EXPECT_FALSE(generateGaze(c, 1, 10).ok());
    c = {};
    c.saccade_min_deg = 50;  // above the max
    EXPECT_FALSE(generateGaze(c, 1, 10).ok());
    EXPECT_FALSE(generateGaze({}, 1, 0).ok());
}

TEST(GazeAt, HoldsTheNewestSample) {
    GazeTrace t;
    t.samples = {{0.0, {1, 1}}, {8.0, {2, 2}}, {16.0, {3, 3}}};
    EXPECT_EQ(gazeAt(t, -5.0).x_deg, 1.0);
    EXPECT_EQ(gazeAt(t, 7.99).x_deg, 1.0);
    EXPECT_EQ(gazeAt(t, 8.0).x_deg, 2.0);
    EXPECT_EQ(gazeAt(t, 100.0).x_deg, 3.0);
}

TEST(GazeCsv, RoundTrips) {
    const GazeTrace t = generate(4, 300);
    auto back = parseGazeCsv(gazeTraceToCsv(t), "gaze.csv");
    ASSERT_TRUE(back.ok()) << back.error();
    ASSERT_EQ(back->samples.size(), t.samples.size());
    for (size_t i = 0; i < t.samples.size(); ++i) {
        EXPECT_NEAR(back->samples[i].t_ms, t.samples[i].t_ms, 1e-6);
        EXPECT_NEAR(back->samples[i].gaze.x_deg, t.samples[i].gaze.x_deg, 1e-6);
        EXPECT_NEAR(back->samples[i].gaze.y_deg, t.samples[i].gaze.y_deg, 1e-6);
    }
}

TEST(GazeCsv, RejectsMalformedFilesWithALineNumber) {
    const std::string h = "t_ms,x_deg,y_deg\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"", "empty file"},
        {"t,x,y\n0,0,0\n", "gaze.csv:1: header must be"},
        {h, "no samples"},
        {h + "0,1,2\n8,1\n", "gaze.csv:3: only 2 fields"},
        {h + "0,1,2,3\n", "gaze.csv:2: more than 3 fields"},
        {h + "0,1,x\n", "gaze.csv:2: field 3 'x'"},
        {h + "0,1,nan\n", "gaze.csv:2: field 3"},
        {h + "0,1,\n", "gaze.csv:2: field 3 ''"},
        {h + "0,1,2\n0,1,2\n", "gaze.csv:3: t_ms 0 does not increase"},
        {h + "0,100,2\n", "gaze.csv:2: gaze (100, 2) deg beyond"},
        {h + "0,1,2\n\n8,1,2\n", "gaze.csv:4: data after a blank line"},
        {h + "0, 1,2\n", "gaze.csv:2: field 2"},
    };
    for (const auto& [text, message] : cases) {
        auto r = parseGazeCsv(text, "gaze.csv");
        ASSERT_FALSE(r.ok()) << text;
        EXPECT_THAT(r.error(), HasSubstr(message)) << text;
    }
    EXPECT_TRUE(parseGazeCsv(h + "0,1,2\r\n8,1,2\r\n\n", "gaze.csv").ok());
}

TEST(GazeCsv, SurvivesRandomMutation) {
    const std::string good = gazeTraceToCsv(generate(2, 50));
    std::mt19937 rng(12);
    std::uniform_int_distribution<size_t> pos(0, good.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    int rejected = 0;
    for (int trial = 0; trial < 1000; ++trial) {
        std::string s = good;
        s[pos(rng)] = static_cast<char>(byte(rng));
        auto r = parseGazeCsv(s, "mutated.csv");
        if (!r.ok()) {
            ++rejected;
            EXPECT_THAT(r.error(), HasSubstr("mutated.csv"));
        } else {
            for (const auto& g : r->samples)
                ASSERT_LE(std::fabs(g.gaze.x_deg), 90.0);
        }
    }
    EXPECT_GT(rejected, 500);
}

}  // namespace
}  // namespace qvr
