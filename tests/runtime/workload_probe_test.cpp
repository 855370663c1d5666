// WorkloadProbe's pixel rings (LIWC's pixel input) against the eccentricity of every grid sample
// computed from scratch by EyeGeometry::eccentricityDeg: the probe caches the grid's directions,
// and must count exactly the same pixels into the same rings for any gaze and any ring width (it
// finds a sample's ring from its cosine through a table, not an acos).
#include "qvr/runtime/workload_probe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "qvr/foveation/eye_geometry.h"

namespace qvr::runtime {
namespace {

std::vector<double> referenceRings(const HmdProfile& profile, const Gaze& gaze, double ring_deg,
                                   int rings) {
    const EyeGeometry g(profile);
    std::vector<double> out(static_cast<size_t>(rings), 0.0);
    const int w = g.width(), h = g.height();
    const int sx = std::max(1, (w + 127) / 128), sy = std::max(1, (h + 127) / 128);
    for (int y0 = 0; y0 < h; y0 += sy)
        for (int x0 = 0; x0 < w; x0 += sx) {
            const int bw = std::min(sx, w - x0), bh = std::min(sy, h - y0);
            const double e = g.eccentricityDeg(gaze, x0 + 0.5 * bw, y0 + 0.5 * bh);
            const int k = std::clamp(static_cast<int>(e / ring_deg), 0, rings - 1);
            out[static_cast<size_t>(k)] += 2.0 * bw * bh;
        }
    return out;
}

TEST(WorkloadProbe, PixelRingsMatchTheEccentricityOfEverySampleForAnyGaze) {
    for (const auto& [w, h] : {std::pair{1920, 2160}, std::pair{480, 540}, std::pair{333, 97}}) {
        for (const auto& [ring_deg, rings] :
             {std::pair{1.0, 120}, std::pair{0.375, 480}, std::pair{1.5, 30}}) {
            HmdProfile profile;
            profile.width_px = w;
            profile.height_px = h;
            WorkloadProbe probe(profile, nullptr, ring_deg, rings);
            std::mt19937 rng(7);
            std::uniform_real_distribution<double> deg(-30.0, 30.0);
            for (int i = 0; i < 20; ++i) {
                const Gaze gaze{deg(rng), deg(rng)};
                const std::vector<double> got = probe.pixelsPerRing(gaze);
                const auto want =
                    referenceRings(profile, gaze, probe.header().ring_deg, probe.header().rings);
                ASSERT_EQ(got.size(), want.size());
                double total = 0.0;
                for (size_t k = 0; k < want.size(); ++k) {
                    EXPECT_EQ(got[k], want[k]) << w << "x" << h << " ring " << k;
                    total += got[k];
                }
                EXPECT_EQ(total, 2.0 * w * h);  // every pixel of both eyes, once
            }
        }
    }
}

}  // namespace
}  // namespace qvr::runtime
