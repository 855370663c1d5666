// The layer plan (paper §3.1, Eq. 1) as a report: the JSON object and the text `qvr plan`
// prints, both read from one LayerPlan.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

// One layer's rectangle, scale, size and pixel count.
nlohmann::json layerRectJson(const LayerRect& layer);
// The plan's radii, scales, pixel counts per layer and both eyes' rectangles.
nlohmann::json layerPlanJson(const LayerPlan& plan, const HmdProfile& profile);
// The same plan as lines a person reads (the first eye's rectangles; the second mirrors it).
std::string layerPlanText(const LayerPlan& plan, const HmdProfile& profile);

}  // namespace qvr
