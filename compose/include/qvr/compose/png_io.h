// PNG files for looking at display images and feeding layer images to `qvr compose`.
#pragma once

#include <string>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"

namespace qvr {

Status writePng(const std::string& path, const ImageRgba8& image);
Expected<ImageRgba8> readPng(const std::string& path);

}  // namespace qvr
