// PNG reading and writing through libpng's simplified API, so display images can be looked at
// and layer images handed to `qvr compose`.
#include "qvr/compose/png_io.h"

#include <cstring>

#include <png.h>

#include <fmt/format.h>

namespace qvr {

Status writePng(const std::string& path, const ImageRgba8& image) {
    if (image.empty())
        return makeError(fmt::format("png: refusing to write an empty image to {}", path));
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width());
    png.height = static_cast<png_uint_32>(image.height());
    png.format = PNG_FORMAT_RGBA;
    const int ok = png_image_write_to_file(&png, path.c_str(), 0, image.data(),
                                           static_cast<png_int_32>(image.strideElems()), nullptr);
    if (!ok) {
        const std::string message = fmt::format("png: cannot write {}: {}", path, png.message);
        png_image_free(&png);
        return makeError(message);
    }
    return Status::success();
}

Expected<ImageRgba8> readPng(const std::string& path) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.c_str())) {
        return makeError(fmt::format("png: cannot read {}: {}", path, png.message));
    }
    if (png.width == 0 || png.height == 0 || png.width > 16384 || png.height > 16384) {
        png_image_free(&png);
        return makeError(fmt::format("png: {} is {}x{}, outside 1…16384 pixels a side", path,
                                     png.width, png.height));
    }
    png.format = PNG_FORMAT_RGBA;
    ImageRgba8 image(static_cast<int>(png.width), static_cast<int>(png.height));
    if (!png_image_finish_read(&png, nullptr, image.data(),
                               static_cast<png_int_32>(image.strideElems()), nullptr)) {
        const std::string message = fmt::format("png: cannot decode {}: {}", path, png.message);
        png_image_free(&png);
        return makeError(message);
    }
    return image;
}

}  // namespace qvr
