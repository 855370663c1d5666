// net benchmarks: protocol encode/decode, packetize + reassemble, the link emulator's own cost,
// and end-to-end frame transfer between a server and a client on 127.0.0.1 (bytes/s), unshaped
// and through the paper's link profiles. Numbers and command: docs/NETWORK.md.
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "qvr/foveation/hmd_profile.h"
#include "qvr/net/client.h"
#include "qvr/net/link_emulator.h"
#include "qvr/net/server.h"
#include "qvr/net/stream_assembler.h"

namespace qvr::net {
namespace {

FrameRequest sampleRequest(uint32_t frame_id) {
    static const LayerPlanner planner(defaultHmdProfile());
    return makeFrameRequest(frame_id, 0, Pose{}, planner.plan(Gaze{3.0, 2.0}, 12.0));
}

void BM_FrameRequestEncodeDecode(benchmark::State& state) {
    const FrameRequest request = sampleRequest(1);
    for (auto _ : state) {
        const auto wire = encodeControl(request);
        ControlMessage back;
        benchmark::DoNotOptimize(decodeControl(wire, back));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FrameRequestEncodeDecode);

void BM_PacketizeReassemble(benchmark::State& state) {
    const std::vector<uint8_t> frame(static_cast<size_t>(state.range(0)), 0x5A);
    StreamAssembler assembler;
    uint32_t seq = 0, frame_id = 0;
    for (auto _ : state) {
        const auto packets = packetizeStream(1, seq, ++frame_id, 0, true, frame);
        for (const auto& p : packets) {
            MediaPacketView v;
            decodeMediaPacket(p, v);
            assembler.onPacket(v, 0);
        }
        benchmark::DoNotOptimize(assembler.takeCompleted());
    }
    state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_PacketizeReassemble)->Arg(100'000)->Arg(1'000'000);

// The per-datagram cost of sealed media (ChaCha20-Poly1305-IETF, docs/PROTOCOL.md §Sealed
// media): seal on the server, open on the client, for a full 1200-byte payload.
constexpr int kPayloadBytes = 1200;

// A plain media datagram with a full payload.
std::vector<uint8_t> sampleDatagram() {
    uint32_t seq = 0;
    return packetizeStream(1, seq, 1, 0, true, std::vector<uint8_t>(kPayloadBytes, 0x5A))[0];
}

// Times `step(d)` on a fresh copy `d` of `datagram` once an iteration, in payload bytes.
template <typename Step>
void perDatagram(benchmark::State& state, const std::vector<uint8_t>& datagram, Step step) {
    std::vector<uint8_t> d;
    d.reserve(kMaxSealedDatagramBytes);
    for (auto _ : state) {
        d.assign(datagram.begin(), datagram.end());
        step(d);
    }
    state.SetBytesProcessed(state.iterations() * kPayloadBytes);
}

void BM_MediaSealPerDatagram(benchmark::State& state) {
    MediaKey key{};
    key.fill(7);
    perDatagram(state, sampleDatagram(), [&](std::vector<uint8_t>& d) {
        sealMediaPacket(d, key);
        benchmark::DoNotOptimize(d.data());
    });
}
BENCHMARK(BM_MediaSealPerDatagram);

void BM_MediaOpenPerDatagram(benchmark::State& state) {
    MediaKey key{};
    key.fill(7);
    auto sealed = sampleDatagram();
    sealMediaPacket(sealed, key);
    perDatagram(state, sealed, [&](std::vector<uint8_t>& d) {
        benchmark::DoNotOptimize(openMediaPacket(d, key));
    });
}
BENCHMARK(BM_MediaOpenPerDatagram);

// The copy alone, to subtract from the two above.
void BM_MediaCopyPerDatagram(benchmark::State& state) {
    perDatagram(state, sampleDatagram(),
                [](std::vector<uint8_t>& d) { benchmark::DoNotOptimize(d.data()); });
}
BENCHMARK(BM_MediaCopyPerDatagram);

// Sealed control (docs/PROTOCOL.md §Sealed control): the largest message, a 232-byte frame
// request, sealed (encode + encrypt) and opened (decrypt + decode), against the plain
// encode/decode of BM_FrameRequestEncodeDecode.
void BM_ControlSealOpenFrameRequest(benchmark::State& state) {
    ControlKey key{};
    key.fill(9);
    const FrameRequest request = sampleRequest(1);
    uint64_t counter = 0, next = 0;
    for (auto _ : state) {
        const auto wire = sealControl(request, key, counter++);
        ControlMessage back;
        benchmark::DoNotOptimize(openControl(wire, key, next, back));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ControlSealOpenFrameRequest);

void BM_LinkEmulatorPerPacket(benchmark::State& state) {
    LinkSpec c = parseLinkSpec("wifi,delay_ms=5,jitter_ms=1,loss=0.01").value();
    LinkEmulator link(c);
    std::vector<std::vector<uint8_t>> out;
    int64_t now_ns = 0;
    for (auto _ : state) {
        link.send(std::vector<uint8_t>(kMaxDatagramBytes), now_ns);
        now_ns += 50'000;  // 1232 B every 50 µs ≈ 197 Mbit/s, just under the link
        out.clear();
        link.deliver(now_ns, out);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LinkEmulatorPerPacket);

// One frame = four streams of range(0) bytes, requested and received one at a time, like a
// client that waits for each frame: bytes/s is the goodput a frame sees on loopback.
class Echo : public ServerHandler {
public:
    // Set after Server::start returns; read on its network thread.
    std::atomic<Server*> server{nullptr};
    size_t stream_bytes = 0;
    void onFrameRequest(ClientId id, const FrameRequest& r) override {
        for (uint8_t s = 0; s < kMaxStreams; ++s) {
            server.load()->sendStream(id, r.frame_id, s, true,
                                      std::vector<uint8_t>(stream_bytes, s));
        }
    }
};

void loopbackTransfer(benchmark::State& state, const char* link_spec, bool retransmit = true) {
    Echo echo;
    echo.stream_bytes = static_cast<size_t>(state.range(0));
    ServerOptions so;
    so.key = PresharedKey::random();
    so.link = parseLinkSpec(link_spec).value();
    auto server = Server::start(so, echo);
    if (!server) {
        state.SkipWithError(server.error().c_str());
        return;
    }
    echo.server = server->get();
    ClientOptions co;
    co.key = so.key;
    co.retransmit = retransmit;
    Client client(co);
    if (!client.connect("127.0.0.1", (*server)->port()).ok()) {
        state.SkipWithError("connect failed");
        return;
    }
    uint32_t frame_id = 0;
    int64_t complete = 0, incomplete = 0;
    for (auto _ : state) {
        client.sendFrameRequest(sampleRequest(++frame_id));
        int got = 0;
        while (got < kMaxStreams) {
            auto s = client.nextStream(500);
            if (!s.ok() || !s->has_value()) {
                break;
            }
            got += (*s)->frame_id == frame_id ? 1 : 0;
        }
        (got == kMaxStreams ? complete : incomplete) += 1;
    }
    state.SetBytesProcessed(complete * kMaxStreams * state.range(0));
    state.counters["frames_incomplete"] = static_cast<double>(incomplete);
    state.counters["ack_estimate_Mbps"] = client.throughputBps() / 1e6;
    state.counters["packets_nacked"] = static_cast<double>(client.stats().assembler.packets_nacked);
}

void BM_LoopbackFrames_Unshaped(benchmark::State& state) {
    loopbackTransfer(state, "none");
}
void BM_LoopbackFrames_UnshapedNoRetransmit(benchmark::State& state) {
    loopbackTransfer(state, "none", false);
}
void BM_LoopbackFrames_Wifi(benchmark::State& state) {
    loopbackTransfer(state, "wifi");
}
void BM_LoopbackFrames_5g(benchmark::State& state) {
    loopbackTransfer(state, "5g");
}
BENCHMARK(BM_LoopbackFrames_Unshaped)->Arg(25'000)->Arg(250'000)->UseRealTime();
BENCHMARK(BM_LoopbackFrames_UnshapedNoRetransmit)->Arg(250'000)->UseRealTime();
BENCHMARK(BM_LoopbackFrames_Wifi)->Arg(25'000)->Arg(250'000)->UseRealTime();
BENCHMARK(BM_LoopbackFrames_5g)->Arg(250'000)->UseRealTime();

}  // namespace
}  // namespace qvr::net
