// Server transport: accept → PSK handshake → control messages; media through the per-client
// link emulator onto a UDP socket. Every socket and session lives on the one network thread.
#include "qvr/net/server.h"

#include <asio.hpp>
#include <atomic>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

#include "control_io.h"
#include "qvr/core/clock.h"
#include "qvr/core/throughput_estimator.h"

namespace qvr::net {
namespace {

using asio::ip::tcp;
using asio::ip::udp;

asio::steady_timer::time_point steadyAt(int64_t ns) {
    return asio::steady_timer::time_point(std::chrono::nanoseconds(ns));
}

// Adds what a session's link counted since `before` (every field only grows).
void addLinkGrowth(LinkStats& total, const LinkStats& before, const LinkStats& now) {
    total.packets_in += now.packets_in - before.packets_in;
    total.packets_delivered += now.packets_delivered - before.packets_delivered;
    total.dropped_loss += now.dropped_loss - before.dropped_loss;
    total.dropped_queue += now.dropped_queue - before.dropped_queue;
    total.dropped_burst += now.dropped_burst - before.dropped_burst;
    total.reordered += now.reordered - before.reordered;
    total.duplicated += now.duplicated - before.duplicated;
    total.spiked += now.spiked - before.spiked;
    total.bytes_in += now.bytes_in - before.bytes_in;
    total.bytes_delivered += now.bytes_delivered - before.bytes_delivered;
}

}  // namespace

struct Session;

struct Server::Impl {
    Impl(ServerOptions o, ServerHandler& h)
        : options(std::move(o)), handler(h), acceptor(io), udp_socket(io), accept_retry(io) {}
    void accept();
    void onAccepted(tcp::socket socket);

    ServerOptions options;
    ServerHandler& handler;
    asio::io_context io;
    tcp::acceptor acceptor;
    udp::socket udp_socket;
    asio::steady_timer accept_retry;
    std::thread thread;
    bool stopped = false;
    uint16_t port = 0;  // fixed at start, read by any thread
    uint16_t media_port = 0;

    mutable std::mutex mutex;  // guards clients, stats; sessions' own state is io-thread only
    std::map<ClientId, std::shared_ptr<Session>> clients;
    std::vector<std::shared_ptr<Session>> sessions;  // every open connection
    int pending = 0;
    int routing = 0;  // authenticated sessions whose media port is being checked (a slot each)
    ServerStats stats;
    int64_t last_unauth_report_ns = INT64_MIN / 2;
};

struct Session : std::enable_shared_from_this<Session> {
    enum class State { kAwaitHello, kAwaitAuth, kAwaitRoute, kAuthed, kClosed };

    Session(Server::Impl& s, tcp::socket sock)
        : server(s),
          socket(std::move(sock)),
          writer(s.options.max_control_queue),
          handshake_timer(s.io),
          flush_timer(s.io),
          link(s.options.link),
          estimator(s.options.throughput_alpha) {}

    void start() {
        // weak: the writer lives in the session, a strong pointer would keep it alive forever.
        writer.setErrorHandler([weak = weak_from_this()](const asio::error_code&) {
            if (auto self = weak.lock()) {
                self->close();
            }
        });
        handshake_timer.expires_after(
            std::chrono::milliseconds(server.options.handshake_timeout_ms));
        handshake_timer.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            if (!ec && (self->state == State::kAwaitHello || self->state == State::kAwaitAuth)) {
                self->count([](ServerStats& st) { ++st.handshake_timeouts; });
                self->refuse(ByeReason::kTimeout);
            }
        });
        readNext();
    }

    template <typename F>
    void count(F f) {
        std::lock_guard lock(server.mutex);
        f(server.stats);
    }

    void readNext() {
        reader.read(socket, [self = shared_from_this()](detail::ReadResult r) {
            self->onRead(std::move(r));
        });
    }

    void onRead(detail::ReadResult r) {
        if (state == State::kClosed) {
            return;
        }
        last_rx_ns = SteadyClock::instance().nowNs();
        if (r.ec) {
            close();  // the client went away
            return;
        }
        if (r.error == WireError::kWrongVersion && state == State::kAwaitHello) {
            count([&](ServerStats& st) {
                st.control_drops.count(r.error);
                ++st.version_mismatches;
            });
            report("refused a client speaking another protocol version (this server speaks " +
                       std::to_string(kProtocolVersion) + ")",
                   true);
            refuse(ByeReason::kVersionMismatch);
            return;
        }
        const bool keyed = state == State::kAwaitRoute || state == State::kAuthed;
        if (keyed && r.error == WireError::kNone && !r.sealed) {
            r.error = WireError::kUnsealed;  // someone else's bytes in the stream
            r.stream_broken = true;
        }
        if (r.error != WireError::kNone) {
            count([&](ServerStats& st) {
                st.control_drops.count(r.error);
                if (keyed && (r.error == WireError::kBadMac || r.error == WireError::kUnsealed)) {
                    ++st.control_forged;
                } else if (keyed && r.error == WireError::kReplayed) {
                    ++st.control_replayed;
                }
            });
            // A stream that carried a forged or replayed message cannot be trusted further.
            // Before authentication nothing malformed is tolerated; after it, a well-framed
            // but invalid message is dropped and the stream goes on.
            if (r.stream_broken || state != State::kAuthed) {
                count([](ServerStats& st) { ++st.protocol_errors; });
                refuse(ByeReason::kProtocolError);
                return;
            }
            readNext();
            return;
        }
        if (!onMessage(r.message)) {
            return;
        }
        readNext();
    }

    // False when the session ended.
    bool onMessage(const ControlMessage& m) {
        switch (state) {
            case State::kAwaitHello: {
                const auto* hello = std::get_if<ClientHello>(&m);
                if (!hello) {
                    break;
                }
                client_nonce = hello->client_nonce;
                media_port = hello->media_port;
                client_settings = hello->settings;
                server_nonce = randomNonce();
                session_id = randomSessionId();
                ServerChallenge c;
                c.server_nonce = server_nonce;
                c.session_id = session_id;
                c.server_proof =
                    serverProof(server.options.key, client_nonce, server_nonce, session_id);
                state = State::kAwaitAuth;
                return send(c);
            }
            case State::kAwaitAuth: {
                const auto* auth = std::get_if<ClientAuth>(&m);
                if (!auth) {
                    break;
                }
                const Mac expected = clientProof(server.options.key, client_nonce, server_nonce,
                                                 session_id, media_port);
                if (!macEqual(expected, auth->client_proof)) {
                    count([](ServerStats& st) {
                        ++st.auth_failures;
                        st.control_drops.count(WireError::kBadMac);
                    });
                    refuse(ByeReason::kAuthFailed);
                    return false;
                }
                media_key = mediaKey(server.options.key, client_nonce, server_nonce, session_id);
                if (const auto why = settingsMismatch(); why != ByeReason::kNormal) {
                    count([](ServerStats& st) { ++st.settings_refusals; });
                    const SessionSettings& mine = server.options.settings;
                    report(why == ByeReason::kCodecMismatch
                               ? "refused a client: codec mismatch (client " +
                                     codecNameOf(client_settings) + ", server " +
                                     codecNameOf(mine) + ")"
                               : "refused a client: display profile mismatch (client " +
                                     profileTextOf(client_settings) + ", server " +
                                     profileTextOf(mine) + ")",
                           false);
                    refuse(why);
                    return false;
                }
                return admit();
            }
            case State::kAwaitRoute:
                return onRouteMessage(m);
            case State::kAuthed:
                return onAuthedMessage(m);
            case State::kClosed:
                return false;
        }
        count([](ServerStats& st) { ++st.protocol_errors; });
        refuse(ByeReason::kProtocolError);
        return false;
    }

    ByeReason settingsMismatch() const {
        const SessionSettings& mine = server.options.settings;
        if (client_settings.codec != mine.codec) {
            return ByeReason::kCodecMismatch;
        }
        if (client_settings != mine) {
            return ByeReason::kProfileMismatch;
        }
        return ByeReason::kNormal;
    }

    // Tells the operator why a client was refused; unauthenticated causes at most once a second.
    void report(const std::string& what, bool unauthenticated) {
        if (!server.options.on_refusal) {
            return;
        }
        if (unauthenticated) {
            const int64_t now_ns = SteadyClock::instance().nowNs();
            std::lock_guard lock(server.mutex);
            if (now_ns - server.last_unauth_report_ns < 1'000'000'000) {
                return;
            }
            server.last_unauth_report_ns = now_ns;
        }
        server.options.on_refusal(what);
    }

    // After authentication the handshake timer watches for silence instead.
    void armIdle(int64_t after_ms) {
        if (server.options.idle_timeout_ms <= 0) {
            return;
        }
        handshake_timer.expires_after(std::chrono::milliseconds(after_ms));
        handshake_timer.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            if (ec || self->state != State::kAuthed) {
                return;
            }
            const int64_t idle_ms =
                (SteadyClock::instance().nowNs() - self->last_rx_ns) / 1'000'000;
            const int64_t limit = self->server.options.idle_timeout_ms;
            if (idle_ms >= limit) {
                self->count([](ServerStats& st) { ++st.idle_timeouts; });
                self->refuse(ByeReason::kTimeout);
                return;
            }
            self->armIdle(limit - idle_ms);
        });
    }

    // Authenticated, with acceptable settings: takes a slot and starts the return-routability
    // check; the session is admitted (Welcome, media) when the client echoes the token.
    bool admit() {
        handshake_timer.cancel();
        asio::error_code ec;
        const tcp::endpoint peer = socket.remote_endpoint(ec);
        if (ec) {
            close();
            return false;
        }
        int admitted = 0;
        {
            std::lock_guard lock(server.mutex);
            --server.pending;
            pending = false;
            admitted = static_cast<int>(server.clients.size()) + server.routing;
            if (admitted >= server.options.max_clients) {
                ++server.stats.refused_full;
            }
        }
        if (admitted >= server.options.max_clients) {
            refuse(ByeReason::kServerFull);
            return false;
        }
        // From here on every control message in both directions is sealed.
        const SessionKeys keys =
            sessionKeys(server.options.key, client_nonce, server_nonce, session_id);
        reader.seal(keys.client_to_server);
        sealer.start(keys.server_to_client);
        route_key = keys.route;
        // Only this thread changes clients and routing, so `admitted` still holds here. The
        // refusal is sealed: only a key holder learns the server's load.
        if (const Admission a = server.handler.onAdmission(admitted); !a.admit) {
            count([](ServerStats& st) { ++st.refused_capacity; });
            report("refused a headset over capacity: " + a.why, false);
            refuse(ByeReason::kOverCapacity);
            return false;
        }
        {
            std::lock_guard lock(server.mutex);
            ++server.routing;
            state = State::kAwaitRoute;
        }
        route_token = randomRouteToken();
        // Media will go only to the address that authenticated, at the port it named — once
        // the client shows it receives there.
        media_endpoint = udp::endpoint(peer.address(), media_port);
        probeRoute();
        return true;
    }

    // One probe (sent directly, not through the link emulator), then the next or the verdict.
    void probeRoute() {
        if (state != State::kAwaitRoute) {
            return;
        }
        if (probes_sent >= std::max(1, server.options.route_probe_attempts)) {
            count([](ServerStats& st) { ++st.route_failures; });
            refuse(ByeReason::kRouteUnverified);
            return;
        }
        const auto probe =
            sealRouteProbe(session_id, static_cast<uint8_t>(probes_sent), route_token, route_key);
        ++probes_sent;
        asio::error_code ec;
        server.udp_socket.send_to(asio::buffer(probe), media_endpoint, 0, ec);
        handshake_timer.expires_after(
            std::chrono::milliseconds(std::max(1, server.options.route_probe_interval_ms)));
        handshake_timer.async_wait([self = shared_from_this()](const asio::error_code& tec) {
            if (!tec) {
                self->probeRoute();
            }
        });
    }

    bool onRouteMessage(const ControlMessage& m) {
        if (std::holds_alternative<Bye>(m)) {
            close();
            return false;
        }
        const auto* confirm = std::get_if<RouteConfirm>(&m);
        if (!confirm || !tokenEqual(confirm->token, route_token)) {
            count([&](ServerStats& st) {
                if (confirm) {
                    ++st.route_failures;
                } else {
                    ++st.protocol_errors;
                }
            });
            refuse(confirm ? ByeReason::kRouteUnverified : ByeReason::kProtocolError);
            return false;
        }
        handshake_timer.cancel();
        {
            std::lock_guard lock(server.mutex);
            --server.routing;
            server.clients.emplace(session_id, shared_from_this());
            ++server.stats.clients_accepted;
            state = State::kAuthed;
        }
        if (!send(Welcome{session_id, server.media_port})) {
            return false;
        }
        server.handler.onClientConnected(session_id);
        armIdle(server.options.idle_timeout_ms);
        return state == State::kAuthed;
    }

    bool onAuthedMessage(const ControlMessage& m) {
        if (const auto* req = std::get_if<FrameRequest>(&m)) {
            count([](ServerStats& st) { ++st.frame_requests; });
            server.handler.onFrameRequest(session_id, *req);
        } else if (const auto* ack = std::get_if<MediaAck>(&m)) {
            count([](ServerStats& st) { ++st.acks; });
            estimator.onAck(ack->frame_id, ack->bytes_received, SteadyClock::instance().nowNs());
            loss_rate = static_cast<double>(ack->loss_ppm) * 1e-6;
            count([&](ServerStats& st) { st.client_loss_ppm = ack->loss_ppm; });
            throughput_bps = estimator.throughputBps();
            if (estimator.samples() > 0) {
                return send(ThroughputReport{static_cast<uint64_t>(estimator.throughputBps()),
                                             estimator.samples()});
            }
        } else if (const auto* nack = std::get_if<Nack>(&m)) {
            retransmit(*nack);
        } else if (const auto* key = std::get_if<KeyFrameRequest>(&m)) {
            count([](ServerStats& st) { ++st.key_frame_requests; });
            server.handler.onKeyFrameRequest(session_id, *key);
        } else if (std::holds_alternative<KeepAlive>(m)) {
            count([](ServerStats& st) { ++st.keepalives; });  // last_rx_ns is what it is for
        } else if (std::holds_alternative<Bye>(m)) {
            close();
            return false;
        } else {
            count([](ServerStats& st) { ++st.protocol_errors; });  // a handshake message again
        }
        return state == State::kAuthed;
    }

    bool send(const ControlMessage& m) {
        const bool queued = writer.push(socket, sealer.encode(m));
        if (!queued) {
            // The client stopped reading its control channel: drop it rather than grow.
            count([](ServerStats& st) { ++st.protocol_errors; });
            close();
            return false;
        }
        return true;
    }

    // Tell the peer why (best effort, a few bytes into an idle socket), then hang up.
    void refuse(ByeReason reason) {
        if (state == State::kClosed) {
            return;
        }
        // Not while a queued write is in flight: the bytes would interleave (and a sealed Bye
        // would overtake messages with lower counters).
        if (writer.idle()) {
            const std::vector<uint8_t> bye = sealer.encode(Bye{reason});
            asio::error_code ec;
            socket.non_blocking(true, ec);
            asio::write(socket, asio::buffer(bye), ec);
        }
        close();
    }

    void close() {
        if (state == State::kClosed) {
            return;
        }
        const bool was_client = state == State::kAuthed;
        const bool was_routing = state == State::kAwaitRoute;
        state = State::kClosed;
        asio::error_code ec;
        handshake_timer.cancel();
        flush_timer.cancel();
        socket.shutdown(tcp::socket::shutdown_both, ec);
        socket.close(ec);
        writer.clear();
        auto self = shared_from_this();
        {
            std::lock_guard lock(server.mutex);
            if (pending) {
                --server.pending;
                pending = false;
            }
            if (was_routing) {
                --server.routing;
            }
            if (was_client) {
                server.clients.erase(session_id);
            }
            std::erase(server.sessions, self);
        }
        if (was_client) {
            server.handler.onClientGone(session_id);
        }
    }

    void enqueueStream(uint32_t frame_id, uint8_t stream_id, bool key_frame,
                       const std::vector<uint8_t>& bytes) {
        queued_bytes -= static_cast<int64_t>(bytes.size());
        if (state != State::kAuthed) {
            return;
        }
        const int64_t now_ns = SteadyClock::instance().nowNs();
        // A sequence number must never repeat under one key (it is the AEAD nonce): a session
        // about to wrap a stream's 32-bit counter (≈ 5 TB) ends, and the client reconnects.
        const uint32_t data_packets = packetCountFor(static_cast<uint32_t>(bytes.size()));
        // Parity per block, for the largest block and the loss the client last reported.
        const auto fec_parity = static_cast<uint8_t>(
            fecParityFor(std::min<int>(static_cast<int>(data_packets), kFecBlockData), loss_rate,
                         server.options.fec));
        const uint32_t parity_packets =
            parityPacketsFor(static_cast<uint16_t>(data_packets), fec_parity);
        if (seq[stream_id] >
            std::numeric_limits<uint32_t>::max() - (data_packets + parity_packets)) {
            refuse(ByeReason::kNormal);
            return;
        }
        auto packets = packetizeStream(session_id, seq[stream_id], frame_id, stream_id, key_frame,
                                       bytes, fec_parity);
        uint64_t parity_bytes = 0;
        for (size_t i = data_packets; i < packets.size(); ++i) {
            parity_bytes += packets[i].size() + kMediaTagBytes;
        }
        for (auto& p : packets) {
            sealMediaPacket(p, media_key);
        }
        estimator.onSend(frame_id, static_cast<int64_t>(bytes.size()), now_ns);
        auto& kept = history[stream_id];
        for (auto& p : packets) {
            retransmit_budget +=
                server.options.retransmit_budget_ratio * static_cast<double>(p.size());
            if (server.options.retransmit_history_packets > 0) {
                kept.push_back({seq[stream_id] - static_cast<uint32_t>(packets.size()) +
                                    static_cast<uint32_t>(&p - packets.data()),
                                p});
                if (static_cast<int>(kept.size()) > server.options.retransmit_history_packets) {
                    kept.pop_front();
                }
            }
            link.send(std::move(p), now_ns);  // the link counts its own drops
        }
        count([&](ServerStats& st) {
            ++st.streams_sent;
            st.fec_frames += parity_packets > 0 ? 1 : 0;
            st.fec_parity_packets += parity_packets;
            st.fec_parity_bytes += parity_bytes;
        });
        flush();
    }

    // Resends what the client asked for from the history, through the link like any packet.
    void retransmit(const Nack& nack) {
        auto& kept = history[nack.stream_id];
        const int64_t now_ns = SteadyClock::instance().nowNs();
        uint64_t resent = 0, missing = 0, refused = 0, resent_bytes = 0;
        for (int i = 0; i < 64; ++i) {
            if (!((nack.missing_mask >> i) & 1)) {
                continue;
            }
            // History packets have consecutive sequence numbers (one counter per stream).
            const uint32_t want = nack.first_seq + static_cast<uint32_t>(i);
            const int64_t offset =
                kept.empty() ? -1 : static_cast<int32_t>(want - kept.front().seq);
            if (offset < 0 || offset >= static_cast<int64_t>(kept.size())) {
                ++missing;
                continue;
            }
            Sent& sent = kept[static_cast<size_t>(offset)];
            if (sent.resent >= server.options.max_retransmissions_per_packet ||
                retransmit_budget < static_cast<double>(sent.bytes.size())) {
                ++refused;  // bounds what NACKs can draw: ≤ (1 + max) × what was sent
                continue;
            }
            ++sent.resent;
            retransmit_budget -= static_cast<double>(sent.bytes.size());
            link.send(sent.bytes, now_ns);
            resent_bytes += sent.bytes.size();
            ++resent;
        }
        count([&](ServerStats& st) {
            ++st.nacks;
            st.packets_retransmitted += resent;
            st.packets_not_in_history += missing;
            st.retransmissions_refused += refused;
            st.bytes_retransmitted += resent_bytes;
        });
        flush();
    }

    void flush() {
        if (state != State::kAuthed) {
            return;
        }
        out.clear();
        link.deliver(SteadyClock::instance().nowNs(), out);
        uint64_t sent = 0, failed = 0;
        for (const auto& p : out) {
            asio::error_code ec;
            server.udp_socket.send_to(asio::buffer(p), media_endpoint, 0, ec);
            (ec ? failed : sent) += 1;
        }
        {
            std::lock_guard lock(server.mutex);
            server.stats.packets_sent += sent;
            server.stats.packets_send_failed += failed;
            const LinkStats now_stats = link.stats();
            addLinkGrowth(server.stats.link, link_stats, now_stats);
            link_stats = now_stats;
        }
        const auto next = link.nextDeliveryNs();
        if (next && !flush_armed) {
            flush_armed = true;
            flush_timer.expires_at(steadyAt(*next));
            flush_timer.async_wait([self = shared_from_this()](const asio::error_code& ec) {
                self->flush_armed = false;
                if (!ec) {
                    self->flush();
                }
            });
        }
    }

    Server::Impl& server;
    tcp::socket socket;
    detail::ControlReader reader;
    detail::ControlWriter writer;
    detail::ControlSealer sealer;        // on from the end of the handshake
    asio::steady_timer handshake_timer;  // handshake, then route probes, then idle timeout
    asio::steady_timer flush_timer;
    bool flush_armed = false;
    State state = State::kAwaitHello;
    bool pending = true;
    Nonce client_nonce{};
    Nonce server_nonce{};
    uint64_t session_id = 0;
    uint16_t media_port = 0;
    SessionSettings client_settings;
    MediaKey media_key{};  // seals every datagram of the session (docs/PROTOCOL.md §Sealed media)
    ControlKey route_key{};
    RouteToken route_token{};
    int probes_sent = 0;
    asio::ip::address peer_address;  // fixed at accept
    int64_t accepted_ns = 0;
    int64_t last_rx_ns = 0;  // the last control message (or its start) from the peer
    udp::endpoint media_endpoint;
    LinkEmulator link;
    LinkStats link_stats;  // a copy for other threads, under server.mutex
    ThroughputEstimator estimator;
    std::array<uint32_t, kMaxStreams> seq{};
    struct Sent {
        uint32_t seq;
        std::vector<uint8_t> bytes;
        int resent = 0;  // times NACKed and sent again
    };
    double retransmit_budget = 0.0;  // bytes NACKs may still draw (retransmit_budget_ratio)
    std::array<std::deque<Sent>, kMaxStreams> history;
    std::vector<std::vector<uint8_t>> out;
    std::atomic<int64_t> queued_bytes{0};
    std::atomic<double> throughput_bps{0.0};
    double loss_rate = 0.0;  // from the client's acks; sizes the FEC parity
};

void Server::Impl::accept() {
    acceptor.async_accept([this](const asio::error_code& ec, tcp::socket socket) {
        if (ec) {
            if (ec != asio::error::operation_aborted && !stopped) {
                // e.g. EMFILE: keep serving the clients we have and try again shortly, rather
                // than spin on an error that repeats at once.
                accept_retry.expires_after(std::chrono::milliseconds(100));
                accept_retry.async_wait([this](const asio::error_code& tec) {
                    if (!tec && !stopped) {
                        accept();
                    }
                });
            }
            return;
        }
        onAccepted(std::move(socket));
        accept();
    });
}

void Server::Impl::onAccepted(tcp::socket socket) {
    asio::error_code ec;
    socket.set_option(tcp::no_delay(true), ec);  // small control messages must not wait
    detail::enableKeepAlive(socket);
    const asio::ip::address source = socket.remote_endpoint(ec).address();
    if (ec) {
        return;  // already gone
    }
    std::shared_ptr<Session> session;
    std::shared_ptr<Session> victim;
    {
        std::lock_guard lock(mutex);
        ++stats.connections;
        if (options.max_pending_handshakes <= 0) {
            ++stats.refused_full;
            socket.close(ec);
            return;
        }
        // Unauthenticated connections per source, and the oldest of each source.
        std::map<asio::ip::address, std::pair<int, Session*>> by_source;
        for (const auto& s : sessions) {
            if (!s->pending) {
                continue;
            }
            auto& [n, oldest] = by_source[s->peer_address];
            ++n;
            if (!oldest || s->accepted_ns < oldest->accepted_ns) {
                oldest = s.get();
            }
        }
        Session* evict = nullptr;
        if (const auto it = by_source.find(source);
            it != by_source.end() && it->second.first >= options.max_pending_per_source) {
            evict = it->second.second;  // a source churns only its own slots
        } else if (pending >= options.max_pending_handshakes) {
            int most = 0;  // the source holding the most slots gives one up
            for (const auto& [address, entry] : by_source) {
                if (entry.first > most ||
                    (entry.first == most && entry.second->accepted_ns < evict->accepted_ns)) {
                    most = entry.first;
                    evict = entry.second;
                }
            }
        }
        if (evict) {
            ++stats.pending_evicted;
            victim = evict->shared_from_this();
        }
        ++pending;
        session = std::make_shared<Session>(*this, std::move(socket));
        session->peer_address = source;
        session->accepted_ns = SteadyClock::instance().nowNs();
        sessions.push_back(session);
    }
    if (victim) {
        victim->refuse(ByeReason::kServerFull);  // releases its slot (close() takes the lock)
    }
    session->start();
}

Server::Server(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}

Server::~Server() {
    stop();
}

Expected<std::unique_ptr<Server>> Server::start(ServerOptions options, ServerHandler& handler) {
    auto impl = std::make_unique<Impl>(std::move(options), handler);
    asio::error_code ec;
    const asio::ip::address address = asio::ip::make_address(impl->options.bind_address, ec);
    if (ec) {
        return makeError("server: bad bind address '" + impl->options.bind_address +
                         "': " + ec.message());
    }
    const tcp::endpoint endpoint(address, impl->options.port);
    impl->acceptor.open(endpoint.protocol(), ec);
    if (!ec) {
        // A restarted server must get its port back while old connections sit in TIME_WAIT.
        impl->acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    }
    if (!ec) {
        impl->acceptor.bind(endpoint, ec);
    }
    if (!ec) {
        impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        return makeError("server: cannot listen on " + impl->options.bind_address + ":" +
                         std::to_string(impl->options.port) + ": " + ec.message());
    }
    impl->udp_socket.open(address.is_v4() ? udp::v4() : udp::v6(), ec);
    if (!ec) {
        impl->udp_socket.bind(udp::endpoint(address, 0), ec);
    }
    if (!ec) {
        // Never block the network thread on a full socket buffer: count and drop instead.
        impl->udp_socket.non_blocking(true, ec);
        impl->udp_socket.set_option(asio::socket_base::send_buffer_size(4 << 20), ec);
        ec.clear();
    }
    if (ec) {
        return makeError("server: cannot open the media socket: " + ec.message());
    }
    impl->port = impl->acceptor.local_endpoint(ec).port();
    impl->media_port = impl->udp_socket.local_endpoint(ec).port();
    impl->accept();
    Impl* raw = impl.get();
    impl->thread = std::thread([raw] { raw->io.run(); });
    return std::unique_ptr<Server>(new Server(std::move(impl)));
}

void Server::stop() {
    if (!m_impl || m_impl->stopped) {
        return;
    }
    Impl* impl = m_impl.get();
    asio::post(impl->io, [impl] {
        impl->stopped = true;
        asio::error_code ec;
        impl->acceptor.close(ec);
        impl->accept_retry.cancel();
        std::vector<std::shared_ptr<Session>> sessions;
        {
            std::lock_guard lock(impl->mutex);
            sessions = impl->sessions;
        }
        for (auto& s : sessions) {
            s->close();
        }
        impl->udp_socket.close(ec);
    });
    if (impl->thread.joinable()) {
        impl->thread.join();
    }
    impl->stopped = true;
}

uint16_t Server::port() const {
    return m_impl->port;
}

uint16_t Server::mediaPort() const {
    return m_impl->media_port;
}

Status Server::sendStream(ClientId client, uint32_t frame_id, uint8_t stream_id, bool key_frame,
                          std::vector<uint8_t> bytes) {
    if (stream_id >= kMaxStreams) {
        return makeError("sendStream: stream id " + std::to_string(stream_id) + " ≥ " +
                         std::to_string(kMaxStreams));
    }
    if (bytes.empty() || bytes.size() > kMaxStreamFrameBytes) {
        return makeError("sendStream: " + std::to_string(bytes.size()) + " bytes outside (0, " +
                         std::to_string(kMaxStreamFrameBytes) + "]");
    }
    std::shared_ptr<Session> session;
    {
        std::lock_guard lock(m_impl->mutex);
        const auto it = m_impl->clients.find(client);
        if (it == m_impl->clients.end() || m_impl->stopped) {
            ++m_impl->stats.streams_rejected;
            return makeError("sendStream: client " + std::to_string(client) + " is not connected");
        }
        session = it->second;
        const int64_t size = static_cast<int64_t>(bytes.size());
        if (session->queued_bytes.load() + size > m_impl->options.max_media_queue_bytes) {
            ++m_impl->stats.streams_rejected;
            return makeError("sendStream: media queue of client " + std::to_string(client) +
                             " is full");
        }
        session->queued_bytes += size;
    }
    asio::post(m_impl->io, [session, frame_id, stream_id, key_frame, b = std::move(bytes)] {
        session->enqueueStream(frame_id, stream_id, key_frame, b);
    });
    return Status::success();
}

ServerStats Server::stats() const {
    std::lock_guard lock(m_impl->mutex);
    return m_impl->stats;
}

std::vector<ClientId> Server::clients() const {
    std::lock_guard lock(m_impl->mutex);
    std::vector<ClientId> ids;
    for (const auto& [id, s] : m_impl->clients) {
        ids.push_back(id);
    }
    return ids;
}

double Server::throughputBps(ClientId client) const {
    std::lock_guard lock(m_impl->mutex);
    const auto it = m_impl->clients.find(client);
    return it == m_impl->clients.end() ? 0.0 : it->second->throughput_bps.load();
}

LinkStats Server::linkStats(ClientId client) const {
    std::lock_guard lock(m_impl->mutex);
    const auto it = m_impl->clients.find(client);
    return it == m_impl->clients.end() ? LinkStats{} : it->second->link_stats;
}

}  // namespace qvr::net
