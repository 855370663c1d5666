// bilinearSpans (the shared periphery's warp taps): the vector kernel writes the scalar twin's
// bytes, at the image's edges, past them, on tails shorter than a vector and on spans too far out
// for 32-bit lanes; and a tap's arithmetic is the bilinear filter's.
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "qvr/compose/bilinear_span.h"

#include "../../compose/src/uca_kernel.h"  // the hooks that pick Highway's target

namespace qvr {
namespace {

ImageRgba8 noise(int w, int h, uint32_t seed) {
    ImageRgba8 image(w, h);
    std::mt19937 rng(seed);
    for (size_t i = 0; i < image.sizeBytes(); ++i)
        image.data()[i] = static_cast<uint8_t>(rng() & 255u);
    return image;
}

std::vector<uint8_t> run(bool vector, const ImageRgba8& src, const std::vector<FixedSpan>& s) {
    size_t taps = 0;
    for (const FixedSpan& x : s)
        taps += static_cast<size_t>(x.n);
    std::vector<uint8_t> out(taps * 4 + 64, 0xAB);  // the tail's bytes must stay untouched
    if (vector)
        bilinearSpans(src, s.data(), s.size(), out.data());
    else
        bilinearSpansScalar(src, s.data(), s.size(), out.data());
    return out;
}

void expectVectorKernelWritesTheScalarTwinsBytes() {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
        const int w = 1 + int(rng() % 90), h = 1 + int(rng() % 70);
        const ImageRgba8 src = noise(w, h, uint32_t(trial));
        std::vector<FixedSpan> spans;
        for (int k = 0; k < 6; ++k) {
            std::uniform_int_distribution<int64_t> pos(-(int64_t(20) << 16), int64_t(w + 20) << 16);
            std::uniform_int_distribution<int64_t> step(-(int64_t(3) << 16), int64_t(3) << 16);
            spans.push_back(
                {pos(rng), pos(rng) * h / std::max(w, 1), step(rng), step(rng), int(rng() % 40)});
        }
        spans.push_back({int64_t(1) << 40, -(int64_t(1) << 41), 12345, int64_t(1) << 35, 19});
        // Both taps in int32, the lanes past them in the vector not (UBSan sees an overflow).
        spans.push_back({int64_t(1) << 29, 0, int64_t(1) << 29, 0, 2});
        ASSERT_EQ(run(true, src, spans), run(false, src, spans))
            << "trial " << trial << " on " << bilinearSpanTarget();
    }
}

// Every target compiled in, not only the one this CPU picks (AVX-512's 16 lanes, AVX2's 8, SSE's
// 4 take different tails).
TEST(BilinearSpan, VectorKernelWritesTheScalarTwinsBytesOnEveryTarget) {
    const std::vector<int64_t> targets = detail::ucaAvailableTargets();
    EXPECT_FALSE(targets.empty());
    for (int64_t t : targets) {
        SCOPED_TRACE(detail::ucaTargetName(t));
        detail::ucaSetTargetsForTest(t);
        EXPECT_STREQ(bilinearSpanTarget(), detail::ucaTargetName(t));
        expectVectorKernelWritesTheScalarTwinsBytes();
    }
    detail::ucaSetTargetsForTest(0);  // back to what the CPU has
}

TEST(BilinearSpan, TapsAreTheBilinearFilter) {
    ImageRgba8 src(2, 2);
    const uint8_t v[4] = {0, 100, 200, 40};  // (0,0), (1,0), (0,1), (1,1) in every channel
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 4; ++c)
            src.at(i % 2, i / 2, c) = v[i];
    // A quarter of the way right, half way down: top 25, bottom 160, their middle 92.5 → 93.
    const std::vector<FixedSpan> spans{{1 << 14, 1 << 15, 0, 0, 1},
                                       {-(5 << 16), 9 << 16, 0, 0, 1}};  // clamped to (0, 1)
    const std::vector<uint8_t> out = run(true, src, spans);
    EXPECT_EQ(out[0], 93);
    EXPECT_EQ(out[2], 93);
    EXPECT_EQ(out[3], 255);
    EXPECT_EQ(out[4], 200);
    EXPECT_EQ(out[8], 0xAB);
}

}  // namespace
}  // namespace qvr
