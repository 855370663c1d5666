// LIWC's 64 KB table of fp16 latency-gradient offsets (paper §4.1, §4.3). Half floats through
// GLM's IEEE binary16 packing, so what is stored rounds exactly as the SRAM would.
#include "qvr/controller/liwc_table.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/packing.hpp>

namespace qvr {

static_assert(LiwcTable::kEntries == 32768, "the paper sizes the table at 2^15 entries");
static_assert(LiwcTable::kBytes == 65536, "64 KB of fp16");

LiwcTable::LiwcTable() {
    clear();
}

void LiwcTable::clear() {
    m_entries.fill(glm::packHalf1x16(0.0f));
}

int LiwcTable::bucketOf(double e_deg) {
    if (!(e_deg > 0.0))
        return 0;
    // Compare before converting: a float-to-int cast of a huge value is undefined.
    if (e_deg >= kEccentricityBuckets * kBucketDeg)
        return kEccentricityBuckets - 1;
    return static_cast<int>(e_deg / kBucketDeg);
}

size_t LiwcTable::indexOf(uint16_t motion, int bucket) {
    QVR_CHECK(motion < kMotionCodes && bucket >= 0 && bucket < kEccentricityBuckets);
    return static_cast<size_t>(motion) * kEccentricityBuckets + static_cast<size_t>(bucket);
}

float LiwcTable::offsetMs(uint16_t motion, int bucket) const {
    return glm::unpackHalf1x16(m_entries[indexOf(motion, bucket)]);
}

void LiwcTable::setOffsetMs(uint16_t motion, int bucket, float value_ms) {
    // fp16 saturates at ±65504; an offset of a minute is already meaningless.
    const float v = std::isfinite(value_ms) ? std::clamp(value_ms, -60000.0f, 60000.0f) : 0.0f;
    m_entries[indexOf(motion, bucket)] = glm::packHalf1x16(v);
}

void LiwcTable::fold(uint16_t motion, int bucket, float delta_ms, float alpha) {
    const float old = offsetMs(motion, bucket);
    setOffsetMs(motion, bucket, (1.0f - alpha) * old + alpha * delta_ms);
}

}  // namespace qvr
