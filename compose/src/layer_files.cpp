// A frame's layers and its display image as PNG files (layer_files.h).
#include "qvr/compose/layer_files.h"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "qvr/compose/png_io.h"
#include "qvr/compose/test_pattern.h"

namespace qvr {

namespace {

constexpr const char* kEyeNames[2] = {"left", "right"};
constexpr const char* kLayerNames[3] = {"fovea", "middle", "outer"};

ImageRgba8& layerOf(EyeLayerImages& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}
const ImageRgba8& layerOf(const EyeLayerImages& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}
const LayerRect& rectOf(const EyeLayers& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}

}  // namespace

std::string layerPngPath(const std::string& dir, int eye, int layer) {
    return (std::filesystem::path(dir) /
            fmt::format("{}_{}.png", kEyeNames[eye], kLayerNames[layer]))
        .string();
}

Expected<LayerFrame> readLayerPngs(const std::string& dir, const LayerPlan& plan,
                                   const Pose& render_pose) {
    LayerFrame frame;
    frame.plan = plan;
    frame.render_pose = render_pose;
    for (int eye = 0; eye < 2; ++eye) {
        for (int k = 0; k < 3; ++k) {
            if (rectOf(plan.eyes[static_cast<size_t>(eye)], k).empty())
                continue;
            auto img = readPng(layerPngPath(dir, eye, k));
            if (!img)
                return makeError(img.error());
            layerOf(frame.eyes[static_cast<size_t>(eye)], k) = std::move(*img);
        }
    }
    return frame;
}

Expected<LayerFrame> layerFrameFrom(const std::string& dir, const HmdProfile& profile,
                                    const LayerPlan& plan, const Pose& render_pose) {
    auto frame = dir.empty()
                     ? makeTestPatternFrame(profile, plan, render_pose, 0,
                                            renderTestPattern(profile.width_px, profile.height_px))
                     : readLayerPngs(dir, plan, render_pose);
    if (!frame)
        return frame;
    if (Status st = validateFrame(profile, *frame); !st)
        return makeError(st.error());
    return frame;
}

Status writeLayerPngs(const std::string& dir, const LayerFrame& frame) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    for (int eye = 0; eye < 2; ++eye) {
        for (int k = 0; k < 3; ++k) {
            const ImageRgba8& img = layerOf(frame.eyes[static_cast<size_t>(eye)], k);
            if (img.empty())
                continue;
            if (Status st = writePng(layerPngPath(dir, eye, k), img); !st)
                return st;
        }
    }
    return {};
}

ImageRgba8 sideBySide(const std::array<ImageRgba8, 2>& eyes) {
    ImageRgba8 out(eyes[0].width() * 2, eyes[0].height());
    for (int y = 0; y < out.height(); ++y) {
        for (int eye = 0; eye < 2; ++eye) {
            const uint8_t* src = eyes[static_cast<size_t>(eye)].row(y);
            std::copy(src, src + eyes[0].strideElems(), out.row(y) + eye * eyes[0].strideElems());
        }
    }
    return out;
}

Status writeSideBySidePng(const std::string& path, const std::array<ImageRgba8, 2>& eyes) {
    const std::filesystem::path out_path(path);
    if (out_path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(out_path.parent_path(), ec);
    }
    return writePng(path, sideBySide(eyes));
}

}  // namespace qvr
