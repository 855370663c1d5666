// What the scene loaders share when they close a draw call.
#pragma once

#include <cstdint>
#include <vector>

#include "qvr/scene/scene.h"

namespace qvr::detail {

// Appends `indices` (into scene.vertices) as one more draw call: the batch's range and bounds are
// set here, its texture, lightmap and patch flag are the caller's; the scene's bounds grow.
inline void appendBatch(Scene& scene, SceneBatch batch, const std::vector<uint32_t>& indices) {
    batch.first_index = static_cast<uint32_t>(scene.indices.size());
    batch.index_count = static_cast<uint32_t>(indices.size());
    for (uint32_t i : indices)
        batch.bounds.extend(scene.vertices[i].position);
    scene.bounds.extend(batch.bounds.min);
    scene.bounds.extend(batch.bounds.max);
    scene.indices.insert(scene.indices.end(), indices.begin(), indices.end());
    scene.batches.push_back(batch);
}

}  // namespace qvr::detail
