// Client transport: a connection is an io_context with its TCP and UDP sockets; the handshake
// runs on the caller's thread with a deadline, then a network thread serves the connection
// until it fails or the caller disconnects.
#include "qvr/net/client.h"

#include <asio.hpp>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>

#include "control_io.h"
#include "qvr/core/clock.h"

namespace qvr::net {
namespace {

using asio::ip::tcp;
using asio::ip::udp;

void add(AssemblerStats& a, const AssemblerStats& b) {
    a.packets_accepted += b.packets_accepted;
    a.packets_duplicate += b.packets_duplicate;
    a.packets_late += b.packets_late;
    a.packets_inconsistent += b.packets_inconsistent;
    a.packets_over_budget += b.packets_over_budget;
    a.seq_gap_packets += b.seq_gap_packets;
    a.streams_completed += b.streams_completed;
    a.streams_lost += b.streams_lost;
    a.streams_undecodable += b.streams_undecodable;
    a.streams_held += b.streams_held;
    a.streams_stale += b.streams_stale;
    a.streams_released_early += b.streams_released_early;
    a.nacks += b.nacks;
    a.packets_nacked += b.packets_nacked;
    a.packets_recovered += b.packets_recovered;
    a.fec_packets_recovered += b.fec_packets_recovered;
    a.fec_recoveries += b.fec_recoveries;
    a.fec_parity_received += b.fec_parity_received;
    a.fec_parity_unused += b.fec_parity_unused;
    a.fec_failures += b.fec_failures;
}

AssemblerLimits limitsOf(const ClientOptions& o) {
    AssemblerLimits limits = o.assembler;
    limits.retransmit = o.retransmit;
    return limits;
}

}  // namespace

struct Connection {
    explicit Connection(const ClientOptions& o)
        : writer(o.max_control_queue), expire_timer(io), assembler(limitsOf(o)) {
        last_key_request_ns.fill(std::numeric_limits<int64_t>::min() / 2);
    }
    asio::io_context io;
    tcp::socket control{io};
    udp::socket media{io};
    detail::ControlReader reader;
    detail::ControlWriter writer;
    detail::ControlSealer sealer;  // on from the end of the handshake
    asio::steady_timer expire_timer;
    StreamAssembler assembler;
    uint64_t session_id = 0;
    // One byte more than the largest valid datagram, so an oversized one is seen as such
    // (the kernel truncates to the buffer) instead of passing as a maximal one.
    std::array<uint8_t, kMaxSealedDatagramBytes + 1> datagram{};
    MediaKey media_key{};  // from the handshake: opens every datagram
    std::array<ReplayWindow, kMaxStreams> replay;
    std::array<int64_t, kMaxStreams> last_key_request_ns{};
    std::thread thread;
    bool closed = false;
    int64_t last_tx_ns = 0;  // the last sealed control message sent (the network thread's)
};

struct Client::Impl {
    explicit Impl(ClientOptions o) : options(std::move(o)) {}

    struct Handshake;
    Status handshake(Connection& c, const std::string& host, uint16_t port);
    void startLoops(Connection& c);
    void readControl(Connection& c);
    void readMedia(Connection& c);
    void armExpiry(Connection& c);
    void handleAssembler(Connection& c, int64_t now_ns);
    void sendControl(Connection& c, const ControlMessage& m);
    void fail(Connection& c, Status reason);

    ClientOptions options;
    std::unique_ptr<Connection> conn;  // owned and replaced by the caller's thread only

    mutable std::mutex mutex;  // guards everything below
    std::condition_variable cv;
    std::deque<CompletedStream> ready;
    std::deque<LostStream> lost;
    bool connected = false;
    Status last_error = makeError("never connected");
    ClientStats stats;
    AssemblerStats closed_assembler;  // from connections that ended
    AssemblerStats live_assembler;
    double throughput_bps = 0.0;
};

// One handshake (docs/PROTOCOL.md): hello, the server's challenge and our proof, then sealed
// control, the return-routability probe and the welcome. Its handlers run on the caller's thread
// inside handshake()'s io loop, so it lives on that stack.
struct Client::Impl::Handshake {
    Handshake(Impl& impl_, Connection& c_, std::string where_)
        : impl(impl_), c(c_), where(std::move(where_)), client_nonce(randomNonce()) {}

    Impl& impl;
    Connection& c;
    const std::string where;
    const Nonce client_nonce;
    ServerChallenge challenge;
    ControlKey route_key{};
    uint16_t media_port = 0;
    bool route_echoed = false;
    bool done = false;
    Status result;

    void finish(Status s) {
        if (!done) {
            done = true;
            result = std::move(s);
            // Return at once, even with the probe's receive still pending (a refusal).
            c.io.stop();
        }
    }

    Error connectError(const std::string& what) const {
        return makeError("connect " + where + ": " + what);
    }

    void countIncompatible() {
        std::lock_guard lock(impl.mutex);
        ++impl.stats.incompatible_refusals;
    }

    // Why the server said bye; a refusal of our version or settings, or for capacity, is
    // counted as permanent.
    Error byeError(ByeReason reason) {
        std::string text = "the server " + std::string(byeReasonClientText(reason));
        if (reason == ByeReason::kOverCapacity) {
            std::lock_guard lock(impl.mutex);
            ++impl.stats.capacity_refusals;
        }
        if (reason == ByeReason::kVersionMismatch || reason == ByeReason::kCodecMismatch ||
            reason == ByeReason::kProfileMismatch) {
            countIncompatible();
            if (reason == ByeReason::kVersionMismatch) {
                text += " (this client speaks version " + std::to_string(kProtocolVersion) + ")";
            } else if (reason == ByeReason::kCodecMismatch) {
                text += " (this client: codec " + codecNameOf(impl.options.settings) + ")";
            } else {
                text += " (this client: " + profileTextOf(impl.options.settings) + ")";
            }
        }
        return connectError(text);
    }

    void start(const tcp::resolver::results_type& endpoints) {
        asio::async_connect(
            c.control, endpoints,
            [this](const asio::error_code& cec, const tcp::endpoint&) { onConnected(cec); });
    }

    // Media arrives on the local address the control connection uses.
    asio::error_code openMediaSocket() {
        asio::error_code e;
        c.control.set_option(tcp::no_delay(true), e);
        detail::enableKeepAlive(c.control);
        const auto local = c.control.local_endpoint(e);
        c.media.open(local.protocol() == tcp::v4() ? udp::v4() : udp::v6(), e);
        if (!e) {
            c.media.bind(udp::endpoint(local.address(), 0), e);
        }
        if (!e) {
            c.media.set_option(asio::socket_base::receive_buffer_size(4 << 20), e);
            e.clear();
        }
        return e;
    }

    void onConnected(const asio::error_code& cec) {
        if (cec) {
            finish(connectError(cec.message()));
            return;
        }
        if (const asio::error_code e = openMediaSocket()) {
            finish(connectError("cannot open the media socket: " + e.message()));
            return;
        }
        asio::error_code pe;
        media_port = c.media.local_endpoint(pe).port();
        c.writer.push(c.control,
                      encodeControl(ClientHello{client_nonce, media_port, impl.options.settings}));
        c.reader.read(c.control, [this](detail::ReadResult r) { onChallenge(r); });
    }

    // The server's challenge: check its proof, send ours, and seal control from here on.
    void onChallenge(const detail::ReadResult& r) {
        if (!r.ec && r.error == WireError::kWrongVersion) {
            countIncompatible();
            finish(connectError(
                "the server speaks another protocol version (this client speaks version " +
                std::to_string(kProtocolVersion) + ")"));
            return;
        }
        if (r.ec || r.error != WireError::kNone) {
            finish(connectError("no valid challenge from the server (" +
                                (r.ec ? r.ec.message() : std::string(wireErrorName(r.error))) +
                                ")"));
            return;
        }
        if (const auto* bye = std::get_if<Bye>(&r.message)) {
            finish(byeError(bye->reason));
            return;
        }
        const auto* ch = std::get_if<ServerChallenge>(&r.message);
        if (!ch) {
            finish(connectError("unexpected message in the handshake"));
            return;
        }
        challenge = *ch;
        const ClientOptions& o = impl.options;
        const Mac expected =
            serverProof(o.key, client_nonce, challenge.server_nonce, challenge.session_id);
        if (!macEqual(expected, challenge.server_proof)) {
            {
                std::lock_guard lock(impl.mutex);
                ++impl.stats.server_proof_failures;
                impl.stats.control_drops.count(WireError::kBadMac);
            }
            finish(connectError("the server does not hold the pre-shared key"));
            return;
        }
        c.writer.push(
            c.control,
            encodeControl(ClientAuth{clientProof(o.key, client_nonce, challenge.server_nonce,
                                                 challenge.session_id, media_port)}));
        // Everything after ClientAuth is sealed, both ways (docs/PROTOCOL.md §Sealed control);
        // only a Bye refusing the handshake may still come plain.
        const SessionKeys keys =
            sessionKeys(o.key, client_nonce, challenge.server_nonce, challenge.session_id);
        c.reader.seal(keys.server_to_client);
        c.sealer.start(keys.client_to_server);
        route_key = keys.route;
        // The server probes our media port; echoing the token proves we receive there.
        receiveProbe();
        c.reader.read(c.control, [this](detail::ReadResult w) { onWelcome(w); });
    }

    // The return-routability probe: the first datagram that opens with the route key and names
    // our session is answered with its token over sealed control; anything else is counted.
    void receiveProbe() {
        c.media.async_receive(asio::buffer(c.datagram),
                              [this](const asio::error_code& rec, size_t n) { onProbe(rec, n); });
    }

    void onProbe(const asio::error_code& rec, size_t n) {
        if (rec || done) {
            return;
        }
        RouteToken token{};
        const WireError e = openRouteProbe(std::span<const uint8_t>(c.datagram.data(), n),
                                           route_key, challenge.session_id, token);
        if (e != WireError::kNone) {
            {
                std::lock_guard lock(impl.mutex);
                impl.stats.media_drops.count(e);
            }
            receiveProbe();
            return;
        }
        route_echoed = true;
        c.writer.push(c.control, c.sealer.encode(RouteConfirm{token}));
    }

    void countBadWelcome(const detail::ReadResult& w) {
        std::lock_guard lock(impl.mutex);
        impl.stats.control_drops.count(w.error);
        impl.stats.control_forged +=
            w.error == WireError::kBadMac || (w.error == WireError::kNone && !w.sealed) ? 1 : 0;
        impl.stats.control_replayed += w.error == WireError::kReplayed ? 1 : 0;
    }

    void onWelcome(const detail::ReadResult& w) {
        if (w.ec) {
            finish(connectError("the server closed the connection (" + w.ec.message() + ")"));
            return;
        }
        if (const auto* bye = std::get_if<Bye>(&w.message); bye && w.error == WireError::kNone) {
            finish(byeError(bye->reason));
            return;
        }
        const auto* welcome = std::get_if<Welcome>(&w.message);
        if (w.error != WireError::kNone || !w.sealed || !welcome ||
            welcome->session_id != challenge.session_id || !route_echoed) {
            countBadWelcome(w);
            finish(connectError("no valid welcome from the server"));
            return;
        }
        asio::error_code ue;
        // Only the server's media socket may feed ours.
        c.media.connect(udp::endpoint(c.control.remote_endpoint(ue).address(), welcome->media_port),
                        ue);
        if (ue) {
            finish(connectError(ue.message()));
            return;
        }
        c.session_id = welcome->session_id;
        c.media_key =
            mediaKey(impl.options.key, client_nonce, challenge.server_nonce, challenge.session_id);
        finish(Status::success());
    }

    // Runs the io loop until the handshake ends or the connect timeout passes.
    void runUntilDone() {
        const int timeout_ms = impl.options.connect_timeout_ms;
        const auto deadline =
            std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
        while (!done && !c.io.stopped()) {
            const auto now = std::chrono::steady_clock::now();
            if (now >= deadline) {
                break;
            }
            c.io.run_for(deadline - now);
        }
        if (!done) {
            finish(connectError("timed out after " + std::to_string(timeout_ms) + " ms"));
        }
    }
};

Status Client::Impl::handshake(Connection& c, const std::string& host, uint16_t port) {
    Handshake h(*this, c, host + ":" + std::to_string(port));
    asio::error_code ec;
    tcp::resolver resolver(c.io);
    const auto endpoints = resolver.resolve(host, std::to_string(port), ec);
    if (ec) {
        return h.connectError("cannot resolve: " + ec.message());
    }
    h.start(endpoints);
    // Replaced by the connection's handler before the network thread starts (startLoops).
    c.writer.setErrorHandler(
        [&h](const asio::error_code& we) { h.finish(h.connectError(we.message())); });
    h.runUntilDone();
    if (!h.result.ok()) {
        // Cancel what is in flight and let the handlers see it before the state goes away.
        c.control.close(ec);
        c.media.close(ec);
        c.io.restart();
        c.io.run();
    }
    return h.result;
}

void Client::Impl::fail(Connection& c, Status reason) {
    if (c.closed) {
        return;
    }
    c.closed = true;
    asio::error_code ec;
    c.expire_timer.cancel();
    c.control.shutdown(tcp::socket::shutdown_both, ec);
    c.control.close(ec);
    c.media.close(ec);
    c.writer.clear();
    {
        std::lock_guard lock(mutex);
        connected = false;
        last_error = std::move(reason);
        ++stats.disconnects;
        add(closed_assembler, c.assembler.stats());
        live_assembler = {};
    }
    cv.notify_all();
}

void Client::Impl::sendControl(Connection& c, const ControlMessage& m) {
    if (c.closed) {
        return;
    }
    c.last_tx_ns = SteadyClock::instance().nowNs();
    const bool queued = c.writer.push(c.control, c.sealer.encode(m));
    if (!queued) {
        fail(c, makeError("the server stopped reading control messages"));
    }
}

void Client::Impl::readControl(Connection& c) {
    c.reader.read(c.control, [this, &c](detail::ReadResult r) {
        if (c.closed) {
            return;
        }
        if (r.ec) {
            fail(c, makeError("connection to the server lost: " + r.ec.message()));
            return;
        }
        if (r.error == WireError::kNone && !r.sealed) {
            r.error = WireError::kUnsealed;  // after the handshake only sealed messages count
            r.stream_broken = true;
        }
        if (r.error != WireError::kNone) {
            {
                std::lock_guard lock(mutex);
                stats.control_drops.count(r.error);
                if (r.error == WireError::kBadMac || r.error == WireError::kUnsealed) {
                    ++stats.control_forged;
                } else if (r.error == WireError::kReplayed) {
                    ++stats.control_replayed;
                }
            }
            if (r.stream_broken) {
                fail(c, makeError(std::string("protocol error from the server: ") +
                                  std::string(wireErrorName(r.error))));
                return;
            }
        } else if (const auto* report = std::get_if<ThroughputReport>(&r.message)) {
            std::lock_guard lock(mutex);
            throughput_bps = static_cast<double>(report->throughput_bps);
        } else if (const auto* bye = std::get_if<Bye>(&r.message)) {
            fail(c, makeError("the server " + std::string(byeReasonClientText(bye->reason))));
            return;
        }
        readControl(c);
    });
}

void Client::Impl::readMedia(Connection& c) {
    c.media.async_receive(asio::buffer(c.datagram), [this, &c](const asio::error_code& ec,
                                                               size_t n) {
        if (c.closed || ec == asio::error::operation_aborted) {
            return;
        }
        // Other errors (an ICMP unreachable from an earlier send) do not end the session; the
        // control connection is what says the server is gone.
        if (!ec) {
            const int64_t now_ns = SteadyClock::instance().nowNs();
            // Forged or altered datagrams stop at the tag, before any field is believed;
            // authentic ones are then checked like any packet, and each is taken only once.
            const std::span<uint8_t> sealed(c.datagram.data(), n);
            if (isRouteProbe(sealed)) {
                readMedia(c);  // a repeat of the probe we already answered
                return;
            }
            MediaPacketView view;
            WireError e = openMediaPacket(sealed, c.media_key);
            if (e == WireError::kNone) {
                e = decodeMediaPacket(sealed.first(n - kMediaTagBytes), view);
            }
            if (e == WireError::kNone && view.header.session_id != c.session_id) {
                e = WireError::kWrongSession;
            }
            if (e == WireError::kNone && !c.replay[view.header.stream_id].accept(view.header.seq)) {
                e = WireError::kReplayed;
            }
            if (e != WireError::kNone) {
                std::lock_guard lock(mutex);
                stats.media_drops.count(e);
            } else {
                c.assembler.onPacket(view, now_ns);
                handleAssembler(c, now_ns);
            }
        }
        readMedia(c);
    });
}

void Client::Impl::armExpiry(Connection& c) {
    // Often enough that a lost tail (AssemblerLimits::tail_nack_ns) is asked for promptly.
    c.expire_timer.expires_after(std::chrono::milliseconds(5));
    c.expire_timer.async_wait([this, &c](const asio::error_code& ec) {
        if (ec || c.closed) {
            return;
        }
        const int64_t now_ns = SteadyClock::instance().nowNs();
        c.assembler.expire(now_ns);
        handleAssembler(c, now_ns);
        // Nothing sent for a while (the headset renders everything itself): say we are here,
        // or the server's idle timeout ends the session.
        if (c.last_tx_ns == 0) {
            c.last_tx_ns = now_ns;
        }
        if (options.keepalive_ms > 0 &&
            now_ns - c.last_tx_ns >= int64_t{options.keepalive_ms} * 1'000'000) {
            sendControl(c, KeepAlive{static_cast<uint64_t>(now_ns)});
            std::lock_guard lock(mutex);
            ++stats.keepalives_sent;
        }
        armExpiry(c);
    });
}

void Client::Impl::handleAssembler(Connection& c, int64_t now_ns) {
    uint8_t need_key = c.assembler.takeLossMask();
    uint32_t trigger_frame = 0;
    std::vector<MediaAck> acks;
    const auto loss_ppm = static_cast<uint32_t>(std::lround(c.assembler.lossRate() * 1e6));
    const std::vector<LostStream> lost_now = c.assembler.takeLost();
    for (const LostStream& l : lost_now) {
        acks.push_back({l.frame_id, l.stream_id, false, l.packets_received, l.bytes_received,
                        static_cast<uint64_t>(l.first_rx_ns), static_cast<uint64_t>(l.last_rx_ns),
                        loss_ppm});
        trigger_frame = l.frame_id;
    }
    auto completed = c.assembler.takeCompleted();
    for (const CompletedStream& s : completed) {
        acks.push_back({s.frame_id, s.stream_id, true, s.packets,
                        static_cast<uint32_t>(s.bytes.size()), static_cast<uint64_t>(s.first_rx_ns),
                        static_cast<uint64_t>(s.last_rx_ns), loss_ppm});
        if (!s.decodable) {
            // Still waiting for the key frame: the request or the key frame itself was lost.
            need_key |= static_cast<uint8_t>(1u << s.stream_id);
            trigger_frame = s.frame_id;
        }
    }
    for (const MediaAck& a : acks) {
        sendControl(c, a);
    }
    for (const Nack& n : c.assembler.takeNacks()) {
        sendControl(c, n);
    }
    // Rate-limit per stream: a request is in flight for key_frame_retry_ms.
    uint8_t mask = 0;
    const int64_t retry_ns = static_cast<int64_t>(options.key_frame_retry_ms) * 1'000'000;
    for (int s = 0; s < kMaxStreams; ++s) {
        if ((need_key >> s & 1) &&
            now_ns - c.last_key_request_ns[static_cast<size_t>(s)] >= retry_ns) {
            mask |= static_cast<uint8_t>(1u << s);
            c.last_key_request_ns[static_cast<size_t>(s)] = now_ns;
        }
    }
    if (mask != 0) {
        sendControl(c, KeyFrameRequest{mask, trigger_frame, KeyFrameReason::kPacketLoss});
    }
    std::lock_guard lock(mutex);
    stats.acks_sent += acks.size();
    stats.key_frame_requests_sent += mask != 0 ? 1 : 0;
    live_assembler = c.assembler.stats();
    for (CompletedStream& s : completed) {
        if (ready.size() >= options.max_ready_streams) {
            ready.pop_front();  // the newest frames matter most to a display
            ++stats.ready_streams_dropped;
        }
        ready.push_back(std::move(s));
    }
    for (const LostStream& l : lost_now) {
        if (lost.size() >= options.max_ready_streams) {
            lost.pop_front();
        }
        lost.push_back(l);
    }
    if (!completed.empty()) {
        cv.notify_all();
    }
}

void Client::Impl::startLoops(Connection& c) {
    c.writer.setErrorHandler([this, &c](const asio::error_code& e) {
        fail(c, makeError("connection to the server lost: " + e.message()));
    });
    readControl(c);
    readMedia(c);
    armExpiry(c);
}

Client::Client(ClientOptions options) : m_impl(std::make_unique<Impl>(std::move(options))) {}

Client::~Client() {
    disconnect();
}

Status Client::connect(const std::string& host, uint16_t port) {
    disconnect();
    Impl& impl = *m_impl;
    auto c = std::make_unique<Connection>(impl.options);
    Status s = impl.handshake(*c, host, port);
    if (!s.ok()) {
        std::lock_guard lock(impl.mutex);
        ++impl.stats.connect_failures;
        impl.last_error = s;
        return s;
    }
    {
        std::lock_guard lock(impl.mutex);
        ++impl.stats.connects;
        impl.connected = true;
        impl.last_error = Status::success();
        impl.throughput_bps = 0.0;
        impl.ready.clear();
        impl.lost.clear();
    }
    Connection* cp = c.get();
    c->io.restart();
    impl.startLoops(*cp);
    c->thread = std::thread([cp] { cp->io.run(); });
    impl.conn = std::move(c);
    return Status::success();
}

void Client::disconnect() {
    Impl& impl = *m_impl;
    if (!impl.conn) {
        return;
    }
    Connection* c = impl.conn.get();
    asio::post(c->io, [&impl, c] {
        if (!c->closed && c->writer.idle()) {
            // Say goodbye if the socket takes it at once; the server also copes without. Not
            // while a queued write is in flight: the bytes would interleave.
            const auto bye = c->sealer.encode(Bye{ByeReason::kNormal});
            asio::error_code ec;
            c->control.non_blocking(true, ec);
            asio::write(c->control, asio::buffer(bye), ec);
        }
        impl.fail(*c, makeError("disconnected by the caller"));
    });
    if (c->thread.joinable()) {
        c->thread.join();
    }
    impl.conn.reset();
}

bool Client::connected() const {
    std::lock_guard lock(m_impl->mutex);
    return m_impl->connected;
}

Status Client::lastError() const {
    std::lock_guard lock(m_impl->mutex);
    return m_impl->last_error;
}

Status Client::sendFrameRequest(const FrameRequest& request) {
    Impl& impl = *m_impl;
    {
        std::lock_guard lock(impl.mutex);
        if (!impl.connected || !impl.conn) {
            return makeError("not connected: " + impl.last_error.error());
        }
        ++impl.stats.frame_requests_sent;
    }
    Connection* c = impl.conn.get();
    asio::post(c->io, [&impl, c, request] { impl.sendControl(*c, request); });
    // The io thread may share this core (the runtime pins the headset's threads to one): let it
    // send now. Without the yield a request waited for the caller's time slice or the next tick
    // (median 2 ms, p90 4.5 ms behind a fovea render on a 2-core guest; docs/NETWORK.md "Handing
    // work to the io thread").
    std::this_thread::yield();
    return Status::success();
}

Status Client::requestKeyFrame(uint8_t stream_mask, uint32_t frame_id, KeyFrameReason reason) {
    Impl& impl = *m_impl;
    if (stream_mask == 0 || stream_mask >= (1u << kMaxStreams)) {
        return makeError("requestKeyFrame: stream mask must name streams 0.." +
                         std::to_string(kMaxStreams - 1));
    }
    {
        std::lock_guard lock(impl.mutex);
        if (!impl.connected || !impl.conn) {
            return makeError("not connected: " + impl.last_error.error());
        }
        ++impl.stats.key_frame_requests_sent;
    }
    Connection* c = impl.conn.get();
    asio::post(c->io, [&impl, c, stream_mask, frame_id, reason] {
        impl.sendControl(*c, KeyFrameRequest{stream_mask, frame_id, reason});
    });
    return Status::success();
}

Expected<std::optional<CompletedStream>> Client::nextStream(int timeout_ms) {
    Impl& impl = *m_impl;
    std::unique_lock lock(impl.mutex);
    impl.cv.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                     [&] { return !impl.ready.empty() || !impl.connected; });
    if (!impl.ready.empty()) {
        CompletedStream s = std::move(impl.ready.front());
        impl.ready.pop_front();
        return std::optional<CompletedStream>(std::move(s));
    }
    if (!impl.connected) {
        return makeError(impl.last_error.ok() ? std::string("not connected")
                                              : impl.last_error.error());
    }
    return std::optional<CompletedStream>();
}

std::vector<LostStream> Client::takeLost() {
    std::lock_guard lock(m_impl->mutex);
    std::vector<LostStream> out(m_impl->lost.begin(), m_impl->lost.end());
    m_impl->lost.clear();
    return out;
}

double Client::throughputBps() const {
    std::lock_guard lock(m_impl->mutex);
    return m_impl->throughput_bps;
}

ClientStats Client::stats() const {
    std::lock_guard lock(m_impl->mutex);
    ClientStats s = m_impl->stats;
    s.assembler = m_impl->closed_assembler;
    add(s.assembler, m_impl->live_assembler);
    return s;
}

}  // namespace qvr::net
