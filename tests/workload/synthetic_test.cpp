// The seeded synthetic workloads: deterministic per seed, valid, sized like the paper's
// Tables 1 and 3, with fovea workloads that swing as the head and gaze move (Fig. 5).
#include "qvr/workload/synthetic.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace qvr {
namespace {

SyntheticSpec shortSpec(SyntheticSpec s, int frames) {
    s.frames = frames;
    return s;
}

bool sameFrames(const WorkloadTrace& a, const WorkloadTrace& b) {
    if (a.frames.size() != b.frames.size())
        return false;
    for (size_t i = 0; i < a.frames.size(); ++i) {
        const WorkloadFrame& x = a.frames[i];
        const WorkloadFrame& y = b.frames[i];
        if (x.time_ms != y.time_ms || x.gaze.x_deg != y.gaze.x_deg ||
            x.gaze.y_deg != y.gaze.y_deg || x.head.orientation != y.head.orientation ||
            x.head.position_m != y.head.position_m ||
            x.triangles_per_ring != y.triangles_per_ring ||
            x.pixels_per_ring != y.pixels_per_ring || x.bits_per_pixel != y.bits_per_pixel ||
            x.static_split.fg_triangles != y.static_split.fg_triangles ||
            x.static_split.fg_screen_fraction != y.static_split.fg_screen_fraction ||
            x.static_split.bg_bytes != y.static_split.bg_bytes ||
            x.static_split.depth_bytes != y.static_split.depth_bytes)
            return false;
    }
    return true;
}

TEST(GenerateSyntheticWorkload, RepeatsExactlyWhenSeedIsTheSame) {
    const SyntheticSpec spec = shortSpec(defaultSyntheticSpec(), 40);
    const WorkloadTrace a = generateSyntheticWorkload(spec);
    const WorkloadTrace b = generateSyntheticWorkload(spec);
    EXPECT_TRUE(sameFrames(a, b));
    EXPECT_EQ(a.header.source, b.header.source);
}

TEST(GenerateSyntheticWorkload, DiffersWhenSeedDiffers) {
    SyntheticSpec spec = shortSpec(defaultSyntheticSpec(), 40);
    const WorkloadTrace a = generateSyntheticWorkload(spec);
    spec.seed = 2;
    const WorkloadTrace b = generateSyntheticWorkload(spec);
    EXPECT_FALSE(sameFrames(a, b));
    int differing = 0;
    for (size_t i = 0; i < a.frames.size(); ++i)
        if (a.frames[i].triangles_per_ring != b.frames[i].triangles_per_ring)
            ++differing;
    EXPECT_GT(differing, 30);
    EXPECT_NE(a.header.source, b.header.source);
}

TEST(GenerateSyntheticWorkload, PassesValidationWhenGenerated) {
    for (const SyntheticSpec& s : paperSyntheticSuite()) {
        const WorkloadTrace t = generateSyntheticWorkload(shortSpec(s, 20));
        const Status st = validateTrace(t);
        EXPECT_TRUE(st.ok()) << s.name << ": " << st.error();
        EXPECT_EQ(t.header.name, s.name);
        EXPECT_EQ(t.header.profile.width_px, s.profile.width_px);
        EXPECT_EQ(t.header.profile.height_px, s.profile.height_px);
        EXPECT_EQ(t.header.batches, s.batches);
        // The rings reach beyond every corner of the field from any gaze in the trace.
        const EyeGeometry geo(t.header.profile);
        for (const WorkloadFrame& f : t.frames)
            EXPECT_GE(t.header.ring_deg * t.header.rings, geo.coverEccentricityDeg(f.gaze));
    }
}

TEST(GenerateSyntheticWorkload, ProducesRequestedFramesWhenTimedAtRefreshRate) {
    const SyntheticSpec spec = shortSpec(defaultSyntheticSpec(), 25);
    const WorkloadTrace t = generateSyntheticWorkload(spec);
    ASSERT_EQ(t.frames.size(), 25u);
    for (size_t i = 0; i < t.frames.size(); ++i) {
        EXPECT_EQ(t.frames[i].index, static_cast<int64_t>(i));
        EXPECT_NEAR(t.frames[i].time_ms, 1000.0 * static_cast<double>(i) / spec.profile.refresh_hz,
                    1e-9);
        // Coarser layers cost more bits per pixel (less spatial redundancy).
        const auto& b = t.frames[i].bits_per_pixel;
        EXPECT_TRUE(std::is_sorted(b.begin(), b.end()));
        EXPECT_GT(b.back(), b.front());
    }
    EXPECT_TRUE(generateSyntheticWorkload(shortSpec(spec, 0)).frames.empty());
}

TEST(GenerateSyntheticWorkload, MatchesSpecSizesWhenSummingRings) {
    SyntheticSpec dflt = defaultSyntheticSpec();
    auto specs = paperSyntheticSuite();
    specs.insert(specs.begin(), dflt);
    for (const SyntheticSpec& s : specs) {
        const WorkloadTrace t = generateSyntheticWorkload(shortSpec(s, 60));
        double tris = 0.0;
        const double full_pixels = 2.0 * s.profile.width_px * s.profile.height_px;
        for (const WorkloadFrame& f : t.frames) {
            tris += sumTotal(f.triangles_per_ring);
            // Shaded pixels integrate to the full frame of both eyes (no overdraw here).
            EXPECT_NEAR(sumTotal(f.pixels_per_ring), full_pixels, 0.02 * full_pixels) << s.name;
        }
        tris /= static_cast<double>(t.frames.size());
        // Both eyes see about triangles_in_view each; objects make it swing either way.
        const double expected = 2.0 * s.triangles_in_view;
        EXPECT_GT(tris, expected / 2.0) << s.name;
        EXPECT_LT(tris, expected * 2.0) << s.name;
    }
}

TEST(GenerateSyntheticWorkload, SwingsFoveaWorkloadWhenHeadAndGazeMove) {
    const WorkloadTrace t = generateSyntheticWorkload(defaultSyntheticSpec());
    ASSERT_EQ(t.frames.size(), 300u);
    double lo = INFINITY, hi = 0.0;
    for (const WorkloadFrame& f : t.frames) {
        const double fovea = sumWithinDeg(f.triangles_per_ring, t.header.ring_deg, 10.0);
        lo = std::min(lo, fovea);
        hi = std::max(hi, fovea);
    }
    EXPECT_GT(lo, 0.0);
    EXPECT_GT(hi / lo, 1.5);
}

TEST(PaperSyntheticSuite, ListsSevenDistinctWorkloadsWhenAsked) {
    const auto suite = paperSyntheticSuite();
    ASSERT_EQ(suite.size(), 7u);
    std::set<std::string> names;
    std::set<uint64_t> seeds;
    int low = 0, high = 0;
    for (const SyntheticSpec& s : suite) {
        EXPECT_EQ(s.name.rfind("synthetic-", 0), 0u) << s.name;
        names.insert(s.name);
        seeds.insert(s.seed);
        if (s.profile.width_px == 1280 && s.profile.height_px == 1600)
            ++low;
        if (s.profile.width_px == 1920 && s.profile.height_px == 2160)
            ++high;
        EXPECT_GT(s.triangles_in_view, 0.0);
        EXPECT_GT(s.batches, 0);
    }
    EXPECT_EQ(names.size(), 7u);
    EXPECT_EQ(seeds.size(), 7u);
    EXPECT_EQ(low, 2);
    EXPECT_EQ(high, 5);
    EXPECT_EQ(defaultSyntheticSpec().frames, 300);
    EXPECT_EQ(defaultSyntheticSpec().name.rfind("synthetic-", 0), 0u);
}

}  // namespace
}  // namespace qvr
