// stb_image decoding (the Debian libstb build) behind the scene loaders' texture lookup.
#include "image_decode.h"

#include <stb_image.h>

#include <cstring>
#include <limits>

#include <fmt/format.h>

namespace qvr {

void halveTexture(SceneTexture& t) {
    const int w = t.width / 2;
    const int h = t.height / 2;
    if (w < 1 || h < 1)
        return;
    std::vector<uint8_t> out(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    const size_t stride = static_cast<size_t>(t.width) * 4;
    for (int y = 0; y < h; ++y) {
        const uint8_t* r0 = t.rgba.data() + static_cast<size_t>(2 * y) * stride;
        const uint8_t* r1 = r0 + stride;
        uint8_t* o = out.data() + static_cast<size_t>(y) * static_cast<size_t>(w) * 4;
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 4; ++c) {
                const int sum =
                    r0[8 * x + c] + r0[8 * x + 4 + c] + r1[8 * x + c] + r1[8 * x + 4 + c];
                o[4 * x + c] = static_cast<uint8_t>((sum + 2) / 4);
            }
        }
    }
    t.width = w;
    t.height = h;
    t.rgba = std::move(out);
}

Expected<SceneTexture> decodeImage(std::span<const uint8_t> bytes, const std::string& name,
                                   int max_side_px) {
    if (bytes.empty() || bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        return makeError(fmt::format("{}: empty or oversized image", name));
    const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
    const int len = static_cast<int>(bytes.size());
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(data, len, &w, &h, &comp))
        return makeError(
            fmt::format("{}: not a decodable image ({})", name, stbi_failure_reason()));
    if (w <= 0 || h <= 0 || w > kMaxDecodedImageSide || h > kMaxDecodedImageSide)
        return makeError(fmt::format("{}: image size {}x{} out of range", name, w, h));
    if (int64_t{w} * h > kMaxDecodedImagePixels)
        return makeError(fmt::format("{}: image size {}x{} over the {} pixel limit", name, w, h,
                                     kMaxDecodedImagePixels));
    stbi_uc* pixels = stbi_load_from_memory(data, len, &w, &h, &comp, 4);
    if (pixels == nullptr)
        return makeError(fmt::format("{}: decode failed ({})", name, stbi_failure_reason()));
    SceneTexture t;
    t.name = name;
    t.width = w;
    t.height = h;
    t.rgba.resize(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    std::memcpy(t.rgba.data(), pixels, t.rgba.size());
    stbi_image_free(pixels);
    while (max_side_px > 0 && (t.width > max_side_px || t.height > max_side_px) && t.width >= 2 &&
           t.height >= 2)
        halveTexture(t);
    return t;
}

}  // namespace qvr
