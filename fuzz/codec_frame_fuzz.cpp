// libFuzzer target for the codec's frame header (codec/frame_header.h, docs/CODEC.md): what the
// headset reads first from every reassembled layer frame. Any bytes parse to a header whose
// payload is exactly the rest and whose checksum matches, or yield an error. The input is also
// split into a sequence of frames (2-byte length prefix) fed through the reference tracker and
// the raw decoder, which must refuse or decode each without crashing. Since a random frame
// rarely carries the right CRC, a chunk whose first byte is odd is instead taken as header
// fields plus payload and packed (a well-formed frame with fuzzed fields) before it goes in.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "qvr/codec/frame_header.h"
#include "qvr/codec/video_codec.h"
#include "qvr/core/check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    auto parsed = qvr::parseFrame(bytes);
    if (parsed.ok()) {
        QVR_CHECK(parsed->payload.size() == parsed->header.payload_bytes);
        QVR_CHECK(qvr::crc32Ieee(parsed->payload) == parsed->header.crc32);
        // Repacking what parsed gives the same bytes.
        const auto again = qvr::packFrame(parsed->header, parsed->payload);
        QVR_CHECK(again.size() == size && std::equal(again.begin(), again.end(), data));
    } else {
        QVR_CHECK(!parsed.error().empty());
    }
    (void)qvr::annexBHasIdr(bytes);

    qvr::CodecConfig config;
    config.backend = "raw";
    auto decoder = qvr::makeVideoDecoder(config);
    QVR_CHECK(decoder.ok());
    qvr::ReferenceTracker tracker;
    size_t pos = 0;
    while (pos + 2 <= size) {
        const size_t n = std::min<size_t>(size - pos - 2, data[pos] | (data[pos + 1] << 8));
        auto frame = bytes.subspan(pos + 2, n);
        pos += 2 + n;
        std::vector<uint8_t> packed;
        if (n >= 9 && (frame[0] & 1)) {
            qvr::FrameHeader h;
            h.flags = frame[1] & 3;
            h.refresh_frames = frame[2] & 15;
            h.frame_id = frame[3] | (frame[4] << 8);
            h.width = frame[5] | (frame[6] << 8);
            h.height = frame[7] | (frame[8] << 8);
            packed = qvr::packFrame(h, frame.subspan(9));
            frame = packed;
        }
        if (auto f = qvr::parseFrame(frame); f.ok()) {
            const qvr::Status admitted = tracker.admit(f->header);
            if (admitted.ok())
                tracker.decoded(f->header, (f->header.frame_id & 1) == 0);
            QVR_CHECK(tracker.recoveringFrames() >= 0);
        }
        auto image = (*decoder)->decode(frame);
        if (image.ok()) {
            QVR_CHECK(image->width() > 0 && image->height() > 0);
            QVR_CHECK(size_t(image->width()) * size_t(image->height()) * 4 +
                          qvr::FrameHeader::kSize ==
                      frame.size());
        } else {
            QVR_CHECK(!image.error().empty());
        }
    }
    return 0;
}
