// A frame's layers as PNG files, and the composed display image as one: how `qvr compose` reads
// the layers a person made ({left,right}_{fovea,middle,outer}.png in one folder), writes the
// layers it used, and shows both eyes side by side.
#pragma once

#include <array>
#include <string>

#include "qvr/compose/uca.h"
#include "qvr/core/expected.h"

namespace qvr {

// `dir`/{left,right}_{fovea,middle,outer}.png; eye 0 left, 1 right; layer 0 fovea, 1 middle,
// 2 outer.
std::string layerPngPath(const std::string& dir, int eye, int layer);

// The layers of `plan` read from `dir` (a layer the plan leaves empty is not read); sizes are
// checked by validateFrame, not here.
Expected<LayerFrame> readLayerPngs(const std::string& dir, const LayerPlan& plan,
                                   const Pose& render_pose);
// The frame to compose: the layers read from `dir` (readLayerPngs), or the built-in test pattern
// rendered for `plan` when `dir` is empty; an error when a file cannot be read or a layer's
// size does not fit the plan (validateFrame).
Expected<LayerFrame> layerFrameFrom(const std::string& dir, const HmdProfile& profile,
                                    const LayerPlan& plan, const Pose& render_pose);
// Every non-empty layer of `frame` written into `dir` (made when missing).
Status writeLayerPngs(const std::string& dir, const LayerFrame& frame);

// The left and right eye images side by side, written to `path` (its folder made when missing).
ImageRgba8 sideBySide(const std::array<ImageRgba8, 2>& eyes);
Status writeSideBySidePng(const std::string& path, const std::array<ImageRgba8, 2>& eyes);

}  // namespace qvr
