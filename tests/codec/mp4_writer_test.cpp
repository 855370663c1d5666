// The display video as MP4: what libavformat reads back (ffprobe's view) is H.264 in MP4 with
// every frame written; bad sizes, paths and files give errors.
#include "qvr/codec/mp4_writer.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

namespace qvr {
namespace {

namespace fs = std::filesystem;

fs::path tempPath(const std::string& name) {
    return fs::temp_directory_path() / ("qvr-mp4-" + std::to_string(getpid()) + "-" + name);
}

ImageRgba8 movingBar(int w, int h, int frame) {
    ImageRgba8 img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool bar = (x + 3 * frame) % w < w / 8;
            img.at(x, y, 0) = bar ? 250 : static_cast<uint8_t>(x);
            img.at(x, y, 1) = static_cast<uint8_t>(y);
            img.at(x, y, 2) = static_cast<uint8_t>(40 + frame);
            img.at(x, y, 3) = 255;
        }
    return img;
}

TEST(Mp4Writer, WritesH264InMp4WithEveryFrame) {
    const fs::path path = tempPath("ok.mp4");
    constexpr int kW = 96, kH = 64, kFrames = 37;
    auto w = Mp4Writer::open(path.string(), kW, kH, 90);
    ASSERT_TRUE(w) << w.error();
    for (int i = 0; i < kFrames; ++i)
        ASSERT_TRUE((*w)->write(movingBar(kW, kH, i)));
    ASSERT_TRUE((*w)->finish());
    auto info = probeVideoFile(path.string());
    ASSERT_TRUE(info) << info.error();
    EXPECT_NE(info->format_name.find("mp4"), std::string::npos) << info->format_name;
    EXPECT_EQ(info->codec_name, "h264");
    EXPECT_EQ(info->width, kW);
    EXPECT_EQ(info->height, kH);
    EXPECT_EQ(info->frames, kFrames);
    EXPECT_NEAR(info->fps, 90.0, 0.5);
    EXPECT_EQ(info->key_frames, 1);  // one a second: 37 frames at 90 fps hold one
    fs::remove(path);
}

TEST(Mp4Writer, RejectsBadSizesRatesAndFrames) {
    const fs::path path = tempPath("bad.mp4");
    EXPECT_FALSE(Mp4Writer::open(path.string(), 95, 64, 90));  // odd: no 4:2:0
    EXPECT_FALSE(Mp4Writer::open(path.string(), 8, 8, 90));
    EXPECT_FALSE(Mp4Writer::open(path.string(), 64, 64, 0));
    EXPECT_FALSE(Mp4Writer::open(path.string(), 64, 64, 90, 60));
    auto w = Mp4Writer::open(path.string(), 64, 64, 30);
    ASSERT_TRUE(w) << w.error();
    const Status st = (*w)->write(movingBar(32, 64, 0));
    ASSERT_FALSE(st);
    EXPECT_NE(st.error().find("32x64"), std::string::npos) << st.error();
    ASSERT_TRUE((*w)->finish());
    EXPECT_FALSE((*w)->write(movingBar(64, 64, 0)));  // after finish
    fs::remove(path);
}

TEST(Mp4Writer, FailsWithAMessageOnAnUnwritablePath) {
    auto w = Mp4Writer::open("/nonexistent-dir/x.mp4", 64, 64, 30);
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().find("/nonexistent-dir/x.mp4"), std::string::npos) << w.error();
}

TEST(ProbeVideoFile, RejectsMissingAndGarbageFiles) {
    EXPECT_FALSE(probeVideoFile("/nonexistent-dir/x.mp4"));
    const fs::path path = tempPath("garbage.mp4");
    {
        std::ofstream out(path, std::ios::binary);
        for (int i = 0; i < 4096; ++i)
            out.put(static_cast<char>((i * 7919) & 0xff));
    }
    EXPECT_FALSE(probeVideoFile(path.string()));
    fs::remove(path);
}

}  // namespace
}  // namespace qvr
