// Layer-stream codec cost (paper §3.2): x264 encode and decode milliseconds and bytes per frame
// for a full eye frame and for periphery layers of the sizes the layer plan produces.
#include <benchmark/benchmark.h>

#include <utility>
#include <vector>

#include "qvr/codec/synthetic_images.h"
#include "qvr/codec/video_codec.h"

namespace qvr {
namespace {

// Eight frames of the detailed pattern panning 4 px per frame: P-frames with real motion.
// content 1 also redraws the grain every frame (like dithered or noisy rendering): the
// expensive case for P-frames.
std::vector<ImageRgba8> clip(int width, int height, int content) {
    std::vector<ImageRgba8> frames;
    for (int i = 0; i < 8; ++i)
        frames.push_back(syntheticDetailedImage(width, height, i * 4,
                                                content == 0 ? 7u : static_cast<uint32_t>(i + 1)));
    return frames;
}

void runCodec(benchmark::State& state, bool decode) {
    const int width = static_cast<int>(state.range(0));
    const int height = static_cast<int>(state.range(1));
    CodecConfig config;
    config.preset = state.range(2) == 0 ? "ultrafast" : "superfast";
    auto encoder = makeVideoEncoder(config);
    auto decoder = makeVideoDecoder(config);
    if (!encoder || !decoder) {
        state.SkipWithError("codec unavailable");
        return;
    }
    const auto frames = clip(width, height, static_cast<int>(state.range(3)));
    // The first frame is the IDR; measure the steady state of P-frames.
    auto first = (*encoder)->encode(frames[0], false);
    if (!first || !(*decoder)->decode(first->bytes)) {
        state.SkipWithError("first frame failed");
        return;
    }
    double encode_ms = 0.0;
    double decode_ms = 0.0;
    double bytes = 0.0;
    size_t i = 1;
    for (auto _ : state) {
        auto enc = (*encoder)->encode(frames[i % frames.size()], false);
        if (!enc) {
            state.SkipWithError(enc.error().c_str());
            return;
        }
        encode_ms += enc->encode_ms;
        bytes += static_cast<double>(enc->bytes.size());
        if (decode) {
            auto dec = (*decoder)->decode(enc->bytes);
            if (!dec) {
                state.SkipWithError(dec.error().c_str());
                return;
            }
            decode_ms += (*decoder)->lastDecodeMs();
        }
        ++i;
    }
    const double n = static_cast<double>(state.iterations());
    state.counters["encode_ms"] = encode_ms / n;
    if (decode)
        state.counters["decode_ms"] = decode_ms / n;
    state.counters["bytes_per_frame"] = bytes / n;
    state.counters["idr_bytes"] = static_cast<double>(first->bytes.size());
    state.SetItemsProcessed(state.iterations());
    state.SetBytesProcessed(state.iterations() * int64_t{width} * height * 4);
}

void BM_Encode(benchmark::State& state) {
    runCodec(state, false);
}
void BM_EncodeDecode(benchmark::State& state) {
    runCodec(state, true);
}

// {width, height, preset: 0 ultrafast 1 superfast, content: 0 panning 1 panning + fresh grain}
void codecArgs(benchmark::internal::Benchmark* b) {
    for (auto [w, h] :
         {std::pair{170, 190}, std::pair{270, 300}, std::pair{540, 600}, std::pair{1920, 2160}})
        b->Args({w, h, 0, 0});
    for (auto [w, h] : {std::pair{170, 190}, std::pair{270, 300}, std::pair{1920, 2160}})
        b->Args({w, h, 0, 1});
    b->Args({270, 300, 1, 0});
    b->Args({1920, 2160, 1, 0});
    // The layer plan's sizes are any width and height: an odd height and a width off 16 beside
    // 270x300 (swscale's unscaled YUV<->RGB kernels want an even height, docs/CODEC.md).
    b->Args({270, 301, 0, 0});
    b->Args({271, 301, 0, 0});
    b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_Encode)->Apply(codecArgs);
BENCHMARK(BM_EncodeDecode)->Apply(codecArgs);

}  // namespace
}  // namespace qvr
