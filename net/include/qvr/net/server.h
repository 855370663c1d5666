// The render server's side of the transport (paper Fig. 7): a TCP control channel per headset,
// accepted only after the pre-shared-key handshake, and the four layer streams sent as UDP
// datagrams through a per-client link emulator. One asio thread serves every client.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/net/auth.h"
#include "qvr/net/fec.h"
#include "qvr/net/link_emulator.h"
#include "qvr/net/protocol.h"

namespace qvr::net {

using ClientId = uint64_t;  // the session id agreed in the handshake

struct ServerOptions {
    std::string bind_address = "127.0.0.1";  // loopback unless the caller opts into more
    uint16_t port = 0;                       // 0: an ephemeral port, see Server::port()
    PresharedKey key;
    int max_clients = 8;
    // Admission under a flood of connections that never authenticate (docs/PROTOCOL.md
    // §Admission): at most this many unauthenticated connections in all and per source address;
    // a new connection beyond either limit evicts the oldest unauthenticated one of the source
    // holding the most, so a flooding source churns only its own slots.
    int max_pending_handshakes = 256;
    int max_pending_per_source = 32;
    int handshake_timeout_ms = 2000;
    // An authenticated session with no control message from its client for this long (a
    // stopped or idle client holding a slot) is ended with Bye(timeout); 0: never.
    int idle_timeout_ms = 10000;
    // Return routability (docs/PROTOCOL.md §Return routability): after authentication the
    // server sends a sealed token to the client's claimed media port, every interval, at most
    // this many times, and admits the session (Welcome, media) only once the client echoes it;
    // unanswered, it ends the session with Bye(media port not verified).
    int route_probe_interval_ms = 250;
    int route_probe_attempts = 4;
    size_t max_control_queue = 256;           // outgoing control messages per client
    int64_t max_media_queue_bytes = 8 << 20;  // accepted by sendStream, not yet in the link
    LinkSpec link;                            // each client gets its own emulator with this
    double throughput_alpha = 0.25;
    // Sent datagrams kept per client and stream for NACKed retransmission (~1.2 MB a stream).
    int retransmit_history_packets = 1024;
    // Each sent datagram is resent at most this often however many NACKs name it (the client
    // asks at most twice), and a session's retransmitted bytes never exceed this fraction of the
    // bytes it first sent: a key holder's NACKs draw at most (1 + ratio) × the media.
    int max_retransmissions_per_packet = 2;
    double retransmit_budget_ratio = 1.0;
    // Reed-Solomon parity on every stream frame, sized from the loss rate the client reports
    // in its acks (fec.h, docs/PROTOCOL.md §Forward error correction); none before a report.
    FecPolicy fec;
    // What a client's ClientHello must carry (codec, display profile); an authenticated client
    // with other settings is refused with Bye(codec / profile mismatch).
    SessionSettings settings;
    // Told why a client was refused for its version or settings (network thread; version
    // mismatches come before authentication, so they are reported at most once a second).
    std::function<void(const std::string&)> on_refusal;
};

// Whether an authenticated headset may join the `admitted` sessions the server holds (those
// serving and those whose media port is being checked); why not, for the server's log.
struct Admission {
    bool admit = true;
    std::string why;
};

// Called on the server's network thread: keep them short (hand work to the render thread),
// and never call Server::stop() from one (it joins that thread). sendStream() is fine.
class ServerHandler {
public:
    virtual ~ServerHandler() = default;
    // Asked once per authenticated headset with acceptable settings, before it takes a slot;
    // a refusal ends it with a sealed Bye(over capacity). Calls are serialised (one thread).
    virtual Admission onAdmission(int /*admitted*/) { return {}; }
    virtual void onClientConnected(ClientId /*client*/) {}
    virtual void onFrameRequest(ClientId /*client*/, const FrameRequest& /*request*/) {}
    virtual void onKeyFrameRequest(ClientId /*client*/, const KeyFrameRequest& /*request*/) {}
    virtual void onClientGone(ClientId /*client*/) {}
};

struct ServerStats {
    uint64_t connections = 0;
    uint64_t clients_accepted = 0;
    uint64_t auth_failures = 0;
    uint64_t handshake_timeouts = 0;
    uint64_t refused_full = 0;
    uint64_t refused_capacity = 0;    // refused by the handler's admission (Bye(over capacity))
    uint64_t pending_evicted = 0;     // unauthenticated connections pushed out by newer ones
    uint64_t idle_timeouts = 0;       // authenticated sessions ended for silence
    uint64_t keepalives = 0;          // KeepAlive messages from clients with nothing else to say
    uint64_t protocol_errors = 0;     // wrong message for the state, or a broken stream
    uint64_t version_mismatches = 0;  // a ClientHello of another protocol version
    uint64_t settings_refusals = 0;   // authenticated, but another codec or display profile
    uint64_t route_failures = 0;      // never proved it receives at its media port
    // Sealed control after the handshake (each ends the session): a tag that does not verify
    // or a plain message; a counter that is not the next one (replayed, reordered, deleted).
    uint64_t control_forged = 0;
    uint64_t control_replayed = 0;
    DropCounters control_drops;
    uint64_t frame_requests = 0;
    uint64_t key_frame_requests = 0;
    uint64_t acks = 0;
    uint64_t streams_sent = 0;
    uint64_t streams_rejected = 0;  // per-client media queue full or client gone
    uint64_t packets_sent = 0;
    uint64_t packets_send_failed = 0;  // the socket buffer was full
    uint64_t nacks = 0;
    uint64_t packets_retransmitted = 0;
    uint64_t packets_not_in_history = 0;   // asked for too late (or never sent)
    uint64_t retransmissions_refused = 0;  // NACKed again after its retransmission budget
    uint64_t bytes_retransmitted = 0;
    uint64_t fec_frames = 0;          // stream frames sent with parity
    uint64_t fec_parity_packets = 0;  // parity datagrams sent (first transmissions)
    uint64_t fec_parity_bytes = 0;    // their bytes on the wire
    uint32_t client_loss_ppm = 0;     // the latest loss rate a client reported
    LinkStats link;                   // every session's emulated link summed (its drops and faults)
};

class Server {
public:
    static Expected<std::unique_ptr<Server>> start(ServerOptions options, ServerHandler& handler);
    ~Server();
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    // Closes every connection at once (clients see the connection end) and joins the thread.
    void stop();
    uint16_t port() const;
    uint16_t mediaPort() const;

    // Thread-safe. Queues one layer's encoded frame for a client; fails without blocking when
    // the client is gone or its queue is full. 0 < bytes ≤ kMaxStreamFrameBytes.
    Status sendStream(ClientId client, uint32_t frame_id, uint8_t stream_id, bool key_frame,
                      std::vector<uint8_t> bytes);

    ServerStats stats() const;
    std::vector<ClientId> clients() const;
    // The ack-based estimate for one client (0 before the first sample or for unknown ids).
    double throughputBps(ClientId client) const;
    LinkStats linkStats(ClientId client) const;

    struct Impl;

private:
    explicit Server(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace qvr::net
