// LIWC's SRAM table (paper §4.1, §4.3): one fp16 latency-gradient offset per (motion code,
// eccentricity bucket): 2^10 × 2^5 = 2^15 entries, 64 KB, the depth the paper sizes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "qvr/controller/motion_codec.h"

namespace qvr {

class LiwcTable {
public:
    static constexpr int kEccentricityBuckets = 32;
    static constexpr double kBucketDeg = 3.0;  // buckets cover 0…96°
    static constexpr size_t kEntries = static_cast<size_t>(kMotionCodes) * kEccentricityBuckets;
    static constexpr size_t kBytes = kEntries * sizeof(uint16_t);

    LiwcTable();

    static int bucketOf(double e_deg);
    static size_t indexOf(uint16_t motion, int bucket);

    // Offsets are stored as IEEE half floats, so reads round to fp16 precision.
    float offsetMs(uint16_t motion, int bucket) const;
    void setOffsetMs(uint16_t motion, int bucket, float value_ms);
    // The paper's update rule: gradient = (1 − α)·gradient′ + α·Δlatency.
    void fold(uint16_t motion, int bucket, float delta_ms, float alpha);
    void clear();

    const uint16_t* raw() const { return m_entries.data(); }

private:
    std::array<uint16_t, kEntries> m_entries;
};

}  // namespace qvr
