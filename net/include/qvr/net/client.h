// The headset's side of the transport: connects with a timeout, proves the pre-shared key,
// sends frame requests, reassembles the four layer streams, acknowledges each stream (the
// server's throughput estimate comes back for LIWC), asks for a key frame after a loss, and
// reports a lost server as an error so the caller can fall back and reconnect later.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/net/auth.h"
#include "qvr/net/protocol.h"
#include "qvr/net/stream_assembler.h"

namespace qvr::net {

struct ClientOptions {
    PresharedKey key;
    int connect_timeout_ms = 2000;  // TCP connect + handshake
    AssemblerLimits assembler;
    // NACK gaps so the server resends the missing packets (one frame's loss then costs a round
    // trip, not a key frame); assembler.retransmit follows this.
    bool retransmit = true;
    int key_frame_retry_ms = 100;  // at most one key-frame request per stream in this time
    // A KeepAlive after this long without any other control message (0: never); well under
    // the server's idle timeout (ServerOptions::idle_timeout_ms, 10 s).
    int keepalive_ms = kKeepAliveIntervalMs;
    size_t max_ready_streams = 256;  // completed streams the caller has not taken yet
    size_t max_control_queue = 256;
    // Sent in the ClientHello; a server with other settings refuses the session (Bye reason).
    SessionSettings settings;
};

struct ClientStats {
    uint64_t connects = 0;
    uint64_t connect_failures = 0;
    uint64_t server_proof_failures = 0;  // the server did not prove the key
    // The server refused our protocol version, codec or display profile (or spoke another
    // version): reconnecting cannot help, lastError() says why.
    uint64_t incompatible_refusals = 0;
    // The server refused us for capacity (Bye(over capacity)): its admitted headsets would fall
    // below its frame-rate floor; this server will not take us while they stay.
    uint64_t capacity_refusals = 0;
    uint64_t disconnects = 0;
    // Sealed control from the server (each ends the connection): a tag that does not verify or
    // a plain message after the handshake; a counter that is not the next one.
    uint64_t control_forged = 0;
    uint64_t control_replayed = 0;
    DropCounters control_drops;
    DropCounters media_drops;
    AssemblerStats assembler;  // accumulated over connections
    uint64_t frame_requests_sent = 0;
    uint64_t acks_sent = 0;
    uint64_t key_frame_requests_sent = 0;
    uint64_t keepalives_sent = 0;        // nothing else sent for kKeepAliveIntervalMs
    uint64_t ready_streams_dropped = 0;  // the caller did not keep up
};

// Used from one thread (the headset's frame loop); the network thread is internal.
class Client {
public:
    explicit Client(ClientOptions options);
    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    // Blocks until the handshake finished, failed or timed out (connect_timeout_ms; a host
    // name is resolved before the clock starts, so prefer an address). Drops any earlier
    // connection; after an error, calling it again is the reconnect.
    Status connect(const std::string& host, uint16_t port);
    void disconnect();
    bool connected() const;
    // Why the last connection ended (success while connected or never connected).
    Status lastError() const;

    Status sendFrameRequest(const FrameRequest& request);
    Status requestKeyFrame(uint8_t stream_mask, uint32_t frame_id, KeyFrameReason reason);

    // The next complete stream, waiting up to timeout_ms: nullopt on timeout, an error once
    // the connection is gone and every stream received before has been taken.
    Expected<std::optional<CompletedStream>> nextStream(int timeout_ms);

    // Streams declared lost since the last call (oldest first, at most max_ready_streams kept):
    // the caller stops waiting for them and re-warps older layers instead (§4.2 frame reuse).
    std::vector<LostStream> takeLost();

    // The server's latest ack-based estimate, 0 before the first.
    double throughputBps() const;
    ClientStats stats() const;

    struct Impl;

private:
    std::unique_ptr<Impl> m_impl;
};

}  // namespace qvr::net
