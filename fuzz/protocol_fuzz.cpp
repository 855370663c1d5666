// libFuzzer target for the qvr wire protocol (docs/PROTOCOL.md): whole control messages, header
// then payload as the transport reads them, media datagrams, and a stream of datagrams through
// the reassembler, the sealed media format (open, seal → open, the replay window), sealed control
// messages (open hostile bytes; seal → open) and the return-routability probe. A decoded
// message must re-encode to bytes that decode again.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "qvr/core/check.h"
#include "qvr/net/auth.h"
#include "qvr/net/protocol.h"
#include "qvr/net/stream_assembler.h"

using namespace qvr::net;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);

    ControlMessage message;
    if (decodeControl(bytes, message) == WireError::kNone) {
        const auto again = encodeControl(message);
        ControlMessage back;
        QVR_CHECK(decodeControl(again, back) == WireError::kNone);
        QVR_CHECK(encodeControl(back) == again);
    }
    // The transport's path: the header alone decides how much payload to read.
    ControlHeader header;
    if (decodeControlHeader(bytes, header) == WireError::kNone) {
        QVR_CHECK(header.payload_bytes <= kMaxControlPayloadBytes);
        const auto payload = bytes.subspan(kControlHeaderBytes);
        ControlMessage m;
        (void)decodeControlPayload(
            header.type, payload.first(std::min<size_t>(payload.size(), header.payload_bytes)), m);
    }

    // Sealed control (docs/PROTOCOL.md §Sealed control): hostile bytes never open without the
    // key's tag and the expected counter; a message that may travel sealed survives seal → open.
    {
        ControlKey key{};
        key.fill(0x24);
        uint64_t next = 0;
        ControlMessage opened;
        const WireError e = openControl(bytes, key, next, opened);
        if (e == WireError::kNone) {
            QVR_CHECK(next == 1 && sealable(static_cast<ControlType>(opened.index() + 1)));
        }
        if (e == WireError::kBadMac || e == WireError::kReplayed || e == WireError::kUnsealed) {
            QVR_CHECK(next == 0);  // only an authentic message with the due counter counts
        }
        if (decodeControl(bytes, message) == WireError::kNone &&
            sealable(static_cast<ControlType>(message.index() + 1))) {
            const uint64_t counter = size;  // any counter
            const auto sealed = sealControl(message, key, counter);
            uint64_t expect = counter;
            ControlMessage back;
            QVR_CHECK(openControl(sealed, key, expect, back) == WireError::kNone);
            QVR_CHECK(expect == counter + 1 && encodeControl(back) == encodeControl(message));
            uint64_t again = counter;  // the same bytes a second time
            QVR_CHECK(openControl(sealed, key, expect, back) == WireError::kReplayed);
            auto flipped = sealed;
            flipped[data[0] % flipped.size()] ^= static_cast<uint8_t>(1u << (size % 8));
            const WireError fe = openControl(flipped, key, again, back);
            QVR_CHECK(fe != WireError::kNone && again == counter);
        }
        RouteToken token{};
        (void)openRouteProbe(bytes, key, 1, token);
    }

    MediaPacketView view;
    if (decodeMediaPacket(bytes, view) == WireError::kNone) {
        QVR_CHECK(view.payload.size() == view.header.payload_bytes);
        QVR_CHECK(view.payload.size() <= kMediaChunkBytes);
    }

    // The sealed form (docs/PROTOCOL.md §Sealed media): opening hostile bytes never crashes and
    // never succeeds without the key's tag; what decodes plain must survive seal → open intact.
    {
        MediaKey key{};
        key.fill(0x42);
        std::vector<uint8_t> sealed(bytes.begin(), bytes.end());
        const WireError e = openMediaPacket(sealed, key);
        QVR_CHECK(e != WireError::kNone || sealed.size() >= kMediaHeaderBytes + kMediaTagBytes);
        if (decodeMediaPacket(bytes, view) == WireError::kNone) {
            std::vector<uint8_t> d(bytes.begin(), bytes.end());
            sealMediaPacket(d, key);
            QVR_CHECK(openMediaPacket(d, key) == WireError::kNone);
            QVR_CHECK(std::equal(bytes.begin(), bytes.end(), d.begin()));
        }
        ReplayWindow window;
        for (size_t i = 0; i + 4 <= size && i < 256; i += 4) {
            uint32_t seq = 0;
            std::memcpy(&seq, data + i, 4);
            const bool first = window.accept(seq);
            QVR_CHECK(!(first && window.accept(seq)));  // never twice
        }
    }

    // The input as a sequence of datagrams, each prefixed by a 2-byte length, fed to one
    // reassembler with a small budget; the clock advances 1 ms per datagram.
    AssemblerLimits limits;
    limits.max_buffered_bytes = 256 << 10;
    limits.retransmit = size > 0 && (data[0] & 1);  // both loss-handling modes
    StreamAssembler assembler(limits);
    size_t pos = 0;
    int64_t now_ns = 0;
    while (pos + 2 <= size) {
        const size_t n = std::min<size_t>(size - pos - 2, data[pos] | (data[pos + 1] << 8));
        const auto datagram = bytes.subspan(pos + 2, n);
        pos += 2 + n;
        now_ns += 1'000'000;
        if (decodeMediaPacket(datagram, view) == WireError::kNone) {
            assembler.onPacket(view, now_ns);
        }
        assembler.expire(now_ns);
        QVR_CHECK(assembler.bufferedBytes() <= limits.max_buffered_bytes);
        for (const CompletedStream& s : assembler.takeCompleted()) {
            QVR_CHECK(s.stream_id < kMaxStreams && !s.bytes.empty());
        }
        (void)assembler.takeLost();
        for (const Nack& nack : assembler.takeNacks()) {
            QVR_CHECK(nack.stream_id < kMaxStreams && nack.missing_mask != 0);
        }
    }
    return 0;
}
