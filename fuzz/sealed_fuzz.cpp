// libFuzzer target for the headset's receive path of sealed media (docs/PROTOCOL.md §Sealed
// media; net/src/client.cpp readMedia): open → decode → session check → replay window →
// reassembler, over a sequence of records. Each record is [op][len lo][len hi][bytes]:
//   op % 3 == 0  the bytes arrive as a datagram from an attacker (no key): never opens;
//   op % 3 == 1  the bytes are a frame the server sends: packetized with 0–3 FEC parity packets
//                per block (op bits 4–5), sealed with the session key and delivered in order;
//                op bit 2 delivers the first datagram twice (replayed), op bit 6 loses one
//                datagram on the way (FEC or the reassembler's loss handling takes over);
//   op % 3 == 2  as 1, with one bit flipped at a fuzz-chosen place in one datagram: that one
//                never opens, the others do.
// Checks: only sealed-and-untouched datagrams open, each is accepted once, the reassembler
// (and its FEC decoder) stays inside its limits and completes only streams that exist.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "qvr/core/check.h"
#include "qvr/net/protocol.h"
#include "qvr/net/stream_assembler.h"

using namespace qvr::net;

namespace {

constexpr uint64_t kSession = 0x5e551014u;

struct Receiver {
    MediaKey key{};
    std::array<ReplayWindow, kMaxStreams> replay;
    StreamAssembler assembler;
    AssemblerLimits limits;
    int64_t now_ns = 0;

    explicit Receiver(const AssemblerLimits& l) : assembler(l), limits(l) { key.fill(0x5a); }

    // The client's path; returns whether the datagram was taken.
    bool receive(std::vector<uint8_t> datagram) {
        now_ns += 1'000'000;
        const std::span<uint8_t> sealed(datagram);
        MediaPacketView view;
        WireError e = openMediaPacket(sealed, key);
        if (e == WireError::kNone)
            e = decodeMediaPacket(sealed.first(sealed.size() - kMediaTagBytes), view);
        if (e == WireError::kNone && view.header.session_id != kSession)
            e = WireError::kWrongSession;
        if (e == WireError::kNone && !replay[view.header.stream_id].accept(view.header.seq))
            e = WireError::kReplayed;
        if (e == WireError::kNone)
            assembler.onPacket(view, now_ns);
        assembler.expire(now_ns);
        QVR_CHECK(assembler.bufferedBytes() <= limits.max_buffered_bytes);
        for (const CompletedStream& s : assembler.takeCompleted())
            QVR_CHECK(s.stream_id < kMaxStreams && !s.bytes.empty());
        (void)assembler.takeLost();
        (void)assembler.takeNacks();
        return e == WireError::kNone;
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    AssemblerLimits limits;
    limits.max_buffered_bytes = 256 << 10;
    limits.retransmit = size > 0 && (data[0] & 0x80);
    Receiver rx(limits);
    uint32_t seq[kMaxStreams] = {};
    size_t pos = 0;
    while (pos + 3 <= size) {
        const uint8_t op = data[pos];
        const size_t n = std::min<size_t>(size - pos - 3, data[pos + 1] | (data[pos + 2] << 8));
        const std::span<const uint8_t> bytes(data + pos + 3, n);
        pos += 3 + n;
        if (op % 3 == 0) {
            // Without the key no datagram opens (a forgery would need to guess a 16-byte tag).
            QVR_CHECK(!rx.receive(std::vector<uint8_t>(bytes.begin(), bytes.end())));
            continue;
        }
        // A server frame: [stream][frame id lo][frame id hi][flip lo][flip hi] then the payload.
        if (n < 6)
            continue;
        const uint8_t stream = bytes[0] % kMaxStreams;
        const uint32_t frame_id = bytes[1] | (bytes[2] << 8);
        const uint32_t flip = bytes[3] | (bytes[4] << 8);
        const auto payload = bytes.subspan(5);
        const auto fec_parity = static_cast<uint8_t>((op >> 4) & 3);
        auto datagrams = packetizeStream(kSession, seq[stream], frame_id, stream, (op & 8) != 0,
                                         payload, fec_parity);
        for (auto& d : datagrams)
            sealMediaPacket(d, rx.key);
        const size_t flipped = op % 3 == 2 ? flip % datagrams.size() : datagrams.size();
        const size_t lost = (op & 0x40) ? (flip >> 3) % datagrams.size() : datagrams.size();
        for (size_t i = 0; i < datagrams.size(); ++i) {
            if (i == lost && i != flipped)
                continue;
            std::vector<uint8_t> d = datagrams[i];
            if (i == flipped) {
                const uint32_t bit = (flip >> 1) % (d.size() * 8);
                d[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
                QVR_CHECK(!rx.receive(std::move(d)));
                continue;
            }
            QVR_CHECK(rx.receive(d));
            if ((op & 4) && i == 0)
                QVR_CHECK(!rx.receive(d));  // the same sealed bytes again: replayed
        }
    }
    return 0;
}
