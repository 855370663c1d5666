// Client and server on 127.0.0.1 (ephemeral ports): handshake accepted and refused, malformed
// control bytes dropped and counted, frames served to several clients, 5% loss through the
// emulator still completing frames with key-frame requests, a killed server surfacing as an
// error and a reconnect to its successor, and the ack-based throughput on a shaped link.
#include <gtest/gtest.h>

#include <array>
#include <asio.hpp>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "qvr/foveation/hmd_profile.h"
#include "qvr/net/auth.h"
#include "qvr/net/client.h"
#include "qvr/net/server.h"

namespace qvr::net {
namespace {

using namespace std::chrono_literals;

PresharedKey testKey() {
    return PresharedKey::fromHex(std::string(64, 'a')).value();
}

// Deterministic content, so the client can check every byte it reassembled.
std::vector<uint8_t> streamBytes(ClientId client, uint32_t frame, uint8_t stream, size_t n) {
    std::vector<uint8_t> v(n);
    uint32_t x = static_cast<uint32_t>(client) ^ (frame * 2654435761u) ^ (stream * 97u + 1u);
    for (auto& b : v) {
        x = x * 1664525u + 1013904223u;
        b = static_cast<uint8_t>(x >> 24);
    }
    return v;
}

// Answers every frame request with the four layer streams, as the render server will; a
// stream goes out as a key frame first and after each key-frame request that names it.
class EchoServer : public ServerHandler {
public:
    explicit EchoServer(size_t stream_bytes) : m_stream_bytes(stream_bytes) {}
    // Set after Server::start returns; read on its network thread.
    std::atomic<Server*> server{nullptr};

    void onClientConnected(ClientId id) override {
        std::lock_guard lock(m_mutex);
        m_need_key[id] = 0xF;
        ++connected;
    }
    void onClientGone(ClientId id) override {
        std::lock_guard lock(m_mutex);
        m_need_key.erase(id);
        ++gone;
    }
    void onFrameRequest(ClientId id, const FrameRequest& request) override {
        ++requests;
        uint8_t key_mask = 0;
        {
            std::lock_guard lock(m_mutex);
            key_mask = std::exchange(m_need_key[id], 0);
        }
        for (uint8_t s = 0; s < kMaxStreams; ++s) {
            const bool key = (key_mask >> s) & 1;
            key_frames_sent += key ? 1 : 0;
            auto st = server.load()->sendStream(
                id, request.frame_id, s, key, streamBytes(id, request.frame_id, s, m_stream_bytes));
            send_errors += st.ok() ? 0 : 1;
        }
    }
    void onKeyFrameRequest(ClientId id, const KeyFrameRequest& request) override {
        ++key_requests;
        std::lock_guard lock(m_mutex);
        m_need_key[id] |= request.stream_mask;
    }

    std::atomic<int> connected{0}, gone{0}, requests{0}, key_requests{0}, key_frames_sent{0},
        send_errors{0};

private:
    size_t m_stream_bytes;
    std::mutex m_mutex;
    std::map<ClientId, uint8_t> m_need_key;
};

FrameRequest request(uint32_t frame_id) {
    static const LayerPlanner planner(defaultHmdProfile());
    return makeFrameRequest(frame_id, 0, Pose{}, planner.plan(Gaze{}, 10.0));
}

std::unique_ptr<Server> startServer(EchoServer& handler, ServerOptions options = {}) {
    if (options.key.toHex() == PresharedKey().toHex()) {
        options.key = testKey();
    }
    auto server = Server::start(std::move(options), handler);
    EXPECT_TRUE(server) << server.error();
    handler.server = server->get();
    return std::move(server).value();
}

ClientOptions clientOptions(PresharedKey key = testKey()) {
    ClientOptions o;
    o.key = key;
    o.connect_timeout_ms = 2000;
    return o;
}

struct Received {
    int streams = 0;
    int decodable = 0;
    int corrupt = 0;
    std::map<uint32_t, int> per_frame;
};

// Takes streams until `streams` arrived or `timeout` passed.
Received receive(Client& client, ClientId id_for_content, size_t stream_bytes, int streams,
                 std::chrono::milliseconds timeout) {
    Received r;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (r.streams < streams && std::chrono::steady_clock::now() < deadline) {
        auto s = client.nextStream(50);
        if (!s) {
            break;
        }
        if (!s->has_value()) {
            continue;
        }
        const CompletedStream& cs = **s;
        ++r.streams;
        r.decodable += cs.decodable ? 1 : 0;
        ++r.per_frame[cs.frame_id];
        if (id_for_content != 0 &&
            cs.bytes != streamBytes(id_for_content, cs.frame_id, cs.stream_id, stream_bytes)) {
            ++r.corrupt;
        }
    }
    return r;
}

TEST(NetTransport, ServesFrameRequestsOverLoopback) {
    EchoServer handler(20'000);
    auto server = startServer(handler);
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    ASSERT_EQ(server->clients().size(), 1u);
    const ClientId id = server->clients()[0];
    for (uint32_t f = 1; f <= 20; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
    }
    const Received r = receive(client, id, 20'000, 80, 5s);
    EXPECT_EQ(r.streams, 80);
    EXPECT_EQ(r.decodable, 80);
    EXPECT_EQ(r.corrupt, 0);
    EXPECT_EQ(r.per_frame.size(), 20u);
    EXPECT_EQ(handler.requests.load(), 20);
    // Acks flowed back: the server has a throughput estimate and told the client.
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while ((client.throughputBps() == 0 || server->stats().acks < 80) &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(5ms);
    }
    EXPECT_GT(client.throughputBps(), 0.0);
    EXPECT_GT(server->throughputBps(id), 0.0);
    EXPECT_EQ(server->stats().acks, 80u);
    EXPECT_EQ(client.stats().assembler.streams_lost, 0u);
    client.disconnect();
    EXPECT_FALSE(client.connected());
}

TEST(NetTransport, WrongKeyIsRefused) {
    EchoServer handler(1000);
    auto server = startServer(handler);
    Client client(clientOptions(PresharedKey::fromPassphrase("not the key").value()));
    const Status s = client.connect("127.0.0.1", server->port());
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().find("pre-shared key"), std::string::npos) << s.error();
    EXPECT_FALSE(client.connected());
    EXPECT_TRUE(server->clients().empty());
    EXPECT_EQ(handler.connected.load(), 0);
    EXPECT_FALSE(client.sendFrameRequest(request(1)).ok());
    EXPECT_FALSE(client.nextStream(10).ok());
}

// A raw peer on the control port: lets tests send exactly the bytes they mean. It has its own
// UDP socket (the media port it claims unless told otherwise), answers the server's
// return-routability probe, and seals and opens control messages after the handshake.
class RawPeer {
public:
    explicit RawPeer(uint16_t port)
        : m_socket(m_io), m_media(m_io, {asio::ip::make_address("127.0.0.1"), 0}) {
        m_socket.connect({asio::ip::make_address("127.0.0.1"), port});
        m_media.set_option(asio::socket_base::receive_buffer_size(8 << 20));
    }
    void send(const std::vector<uint8_t>& bytes) { asio::write(m_socket, asio::buffer(bytes)); }
    // Sealed with the client's key and its next counter (after the handshake).
    std::vector<uint8_t> seal(const ControlMessage& m) {
        return sealControl(m, m_keys.client_to_server, m_send_counter++);
    }
    void sendSealed(const ControlMessage& m) { send(seal(m)); }
    // Reads one control message (opening sealed ones); nullopt when the server closed the
    // connection or sent something this peer cannot decode.
    std::optional<ControlMessage> read() {
        std::vector<uint8_t> raw(kControlHeaderBytes);
        asio::error_code ec;
        asio::read(m_socket, asio::buffer(raw), ec);
        if (ec) {
            return std::nullopt;
        }
        ControlHeader h;
        if (decodeControlHeader(raw, h) != WireError::kNone) {
            return std::nullopt;
        }
        raw.resize(kControlHeaderBytes + h.payload_bytes);
        asio::read(m_socket, asio::buffer(raw.data() + kControlHeaderBytes, h.payload_bytes), ec);
        ControlMessage m;
        if (ec) {
            return std::nullopt;
        }
        const WireError e = h.type == ControlType::kSealed
                                ? openControl(raw, m_keys.server_to_client, m_read_counter, m)
                                : decodeControl(raw, m);
        if (e != WireError::kNone) {
            return std::nullopt;
        }
        return m;
    }
    bool closedByPeer() {
        std::array<uint8_t, 64> buf{};
        asio::error_code ec;
        while (!ec) {
            m_socket.read_some(asio::buffer(buf), ec);
        }
        return ec == asio::error::eof || ec == asio::error::connection_reset;
    }
    // The client side of the handshake with any key; returns the Welcome or what came instead.
    // `claimed_port`: the media port named in the ClientHello (default: this peer's own);
    // `route`: how to answer the server's probe (only possible when it comes to this peer's
    // port).
    enum class Route { kEcho, kSilent, kWrongToken, kSomethingElse };
    std::optional<ControlMessage> handshake(const PresharedKey& key,
                                            std::optional<uint16_t> claimed_port = std::nullopt,
                                            Route route = Route::kEcho) {
        const uint16_t media_port = claimed_port.value_or(mediaPort());
        const Nonce cn = randomNonce();
        send(encodeControl(ClientHello{cn, media_port}));
        auto m = read();
        if (!m || !std::holds_alternative<ServerChallenge>(*m)) {
            return m;
        }
        const auto& ch = std::get<ServerChallenge>(*m);
        m_session = ch.session_id;
        m_keys = sessionKeys(key, cn, ch.server_nonce, ch.session_id);
        m_media_key = mediaKey(key, cn, ch.server_nonce, ch.session_id);
        send(encodeControl(
            ClientAuth{clientProof(key, cn, ch.server_nonce, ch.session_id, media_port)}));
        if (route == Route::kSomethingElse) {
            sendSealed(KeyFrameRequest{1, 0, KeyFrameReason::kStart});
        } else if (route != Route::kSilent && !claimed_port) {
            if (auto token = awaitProbe(2s)) {
                (*token)[0] ^= route == Route::kWrongToken ? 1 : 0;
                sendSealed(RouteConfirm{*token});
            }
        }
        return read();
    }
    // The token of the next valid probe on this peer's media socket, within `timeout`.
    std::optional<RouteToken> awaitProbe(std::chrono::milliseconds timeout) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        m_media.non_blocking(true);
        std::array<uint8_t, 2048> buf{};
        while (std::chrono::steady_clock::now() < deadline) {
            asio::error_code ec;
            if (m_socket.available(ec) > 0) {
                return std::nullopt;  // the server answered on control instead (a refusal)
            }
            const size_t n = m_media.receive(asio::buffer(buf), 0, ec);
            if (ec) {
                std::this_thread::sleep_for(2ms);
                continue;
            }
            RouteToken token{};
            if (openRouteProbe(std::span<const uint8_t>(buf.data(), n), m_keys.route, m_session,
                               token) == WireError::kNone) {
                return token;
            }
        }
        return std::nullopt;
    }
    uint16_t mediaPort() const { return m_media.local_endpoint().port(); }
    asio::ip::udp::socket& media() { return m_media; }
    const MediaKey& mediaKey_() const { return m_media_key; }

private:
    asio::io_context m_io;
    asio::ip::tcp::socket m_socket;
    asio::ip::udp::socket m_media;
    uint64_t m_session = 0;
    SessionKeys m_keys;
    MediaKey m_media_key{};
    uint64_t m_send_counter = 0;
    uint64_t m_read_counter = 0;
};

TEST(NetTransport, ServerRefusesABadProofAndSaysWhy) {
    EchoServer handler(1000);
    auto server = startServer(handler);
    RawPeer peer(server->port());
    auto reply = peer.handshake(PresharedKey::fromPassphrase("guess").value());
    ASSERT_TRUE(reply.has_value());
    ASSERT_TRUE(std::holds_alternative<Bye>(*reply));
    EXPECT_EQ(std::get<Bye>(*reply).reason, ByeReason::kAuthFailed);
    EXPECT_TRUE(peer.closedByPeer());
    EXPECT_EQ(server->stats().auth_failures, 1u);
    EXPECT_EQ(server->stats().control_drops[WireError::kBadMac], 1u);
    EXPECT_EQ(handler.connected.load(), 0);
}

TEST(NetTransport, MalformedControlBytesAreDroppedAndCounted) {
    EchoServer handler(1000);
    auto server = startServer(handler);
    {
        RawPeer peer(server->port());  // not a qvr message: the stream is closed
        peer.send({'G', 'E', 'T', ' ', '/', ' ', 'H', 'T', 'T', 'P'});
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // a header claiming 4 GB of payload
        peer.send({'Q', 'C', kProtocolVersion, 5, 0xFF, 0xFF, 0xFF, 0xFF});
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // another protocol version: refused with the reason
        auto hello = encodeControl(ClientHello{randomNonce(), 1234});
        hello[2] = kProtocolVersion + 1;
        peer.send(hello);
        auto m = peer.read();
        ASSERT_TRUE(m && std::holds_alternative<Bye>(*m));
        EXPECT_EQ(std::get<Bye>(*m).reason, ByeReason::kVersionMismatch);
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // an unknown type, then a frame request before auth
        peer.send({'Q', 'C', kProtocolVersion, 77, 0, 0, 0, 0});
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // truncated: half a header, then the peer leaves
        peer.send({'Q', 'C', kProtocolVersion});
    }
    {
        // After authentication a well-framed but invalid message is dropped and the session
        // goes on: the next valid request is served.
        RawPeer peer(server->port());
        auto welcome = peer.handshake(testKey());
        ASSERT_TRUE(welcome && std::holds_alternative<Welcome>(*welcome));
        FrameRequest bad = request(1);
        bad.e1_deg = std::numeric_limits<float>::quiet_NaN();
        peer.sendSealed(bad);
        peer.sendSealed(request(2));
        const auto deadline = std::chrono::steady_clock::now() + 2s;
        while (handler.requests.load() < 1 && std::chrono::steady_clock::now() < deadline) {
            std::this_thread::sleep_for(5ms);
        }
        EXPECT_EQ(handler.requests.load(), 1);
    }
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (server->stats().control_drops.total() < 5 &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(5ms);
    }
    const ServerStats st = server->stats();
    EXPECT_EQ(st.control_drops[WireError::kBadMagic], 1u);
    EXPECT_EQ(st.control_drops[WireError::kOversized], 1u);
    EXPECT_EQ(st.control_drops[WireError::kWrongVersion], 1u);
    EXPECT_EQ(st.control_drops[WireError::kUnknownType], 1u);
    EXPECT_EQ(st.control_drops[WireError::kBadField], 1u);
    EXPECT_EQ(st.version_mismatches, 1u);
    EXPECT_EQ(st.clients_accepted, 1u);
}

// Codec and display profile travel in the ClientHello; an authenticated client with other
// settings is refused with the reason, which both ends report, and the client counts it as a
// refusal that reconnecting cannot fix.
TEST(NetTransport, MismatchedSettingsAreRefusedWithTheReasonOnBothSides) {
    EchoServer handler(1000);
    ServerOptions o;
    o.settings = makeSessionSettings("x264", "small-320x360", 320, 360, 90.0);
    std::mutex mutex;
    std::vector<std::string> refusals;
    o.on_refusal = [&](const std::string& why) {
        std::lock_guard lock(mutex);
        refusals.push_back(why);
    };
    auto server = startServer(handler, o);
    struct Case {
        SessionSettings settings;
        const char* client_says;
        const char* server_says;
    };
    const Case cases[] = {
        {makeSessionSettings("raw", "small-320x360", 320, 360, 90.0), "codec mismatch",
         "codec mismatch (client raw, server x264)"},
        {makeSessionSettings("x264", "run-480x540", 480, 540, 90.0), "profile mismatch",
         "display profile mismatch (client run-480x540 480x540@90Hz, server small-320x360 "
         "320x360@90Hz)"},
        {makeSessionSettings("x264", "small-320x360", 320, 360, 72.0), "profile mismatch", "@72Hz"},
    };
    for (const Case& c : cases) {
        ClientOptions co = clientOptions();
        co.settings = c.settings;
        Client client(co);
        const Status st = client.connect("127.0.0.1", server->port());
        ASSERT_FALSE(st.ok());
        EXPECT_NE(st.error().find(c.client_says), std::string::npos) << st.error();
        EXPECT_EQ(client.stats().incompatible_refusals, 1u);
        EXPECT_FALSE(client.connected());
    }
    EXPECT_EQ(server->stats().settings_refusals, 3u);
    EXPECT_EQ(server->stats().clients_accepted, 0u);
    EXPECT_EQ(handler.connected.load(), 0);
    {
        std::lock_guard lock(mutex);
        ASSERT_EQ(refusals.size(), 3u);
        for (size_t i = 0; i < 3; ++i)
            EXPECT_NE(refusals[i].find(cases[i].server_says), std::string::npos) << refusals[i];
    }
    // The same settings connect.
    ClientOptions co = clientOptions();
    co.settings = o.settings;
    Client client(co);
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok());
    EXPECT_EQ(client.stats().incompatible_refusals, 0u);
}

// A handler that admits `capacity` sessions and refuses the next, as the render server's
// admission by frame-rate floor does.
class CappedServer : public EchoServer {
public:
    explicit CappedServer(int capacity) : EchoServer(1000), m_capacity(capacity) {}
    Admission onAdmission(int admitted) override {
        {
            std::lock_guard lock(m_asked_mutex);
            m_asked.push_back(admitted);
        }
        if (admitted < m_capacity)
            return {};
        return {false, "a test's capacity of " + std::to_string(m_capacity)};
    }
    std::vector<int> asked() {
        std::lock_guard lock(m_asked_mutex);
        return m_asked;
    }

private:
    int m_capacity;
    std::mutex m_asked_mutex;
    std::vector<int> m_asked;
};

// Over capacity: a sealed Bye(over capacity) after authentication, named by the client and
// counted on both sides as permanent; the admitted session is untouched.
TEST(NetTransport, AHeadsetOverCapacityIsRefusedWithItsReason) {
    CappedServer handler(1);
    ServerOptions o;
    std::mutex mutex;
    std::vector<std::string> refusals;
    o.on_refusal = [&](const std::string& why) {
        std::lock_guard lock(mutex);
        refusals.push_back(why);
    };
    auto server = startServer(handler, o);
    Client first(clientOptions());
    ASSERT_TRUE(first.connect("127.0.0.1", server->port()).ok()) << first.lastError().error();
    Client second(clientOptions());
    const Status st = second.connect("127.0.0.1", server->port());
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().find("at capacity"), std::string::npos) << st.error();
    EXPECT_NE(st.error().find("--min-fps"), std::string::npos) << st.error();
    EXPECT_EQ(second.stats().capacity_refusals, 1u);
    EXPECT_EQ(second.stats().incompatible_refusals, 0u);
    EXPECT_EQ(second.stats().control_forged, 0u);  // the Bye came sealed and verified
    EXPECT_EQ(server->stats().refused_capacity, 1u);
    EXPECT_EQ(server->stats().clients_accepted, 1u);
    EXPECT_EQ(handler.connected.load(), 1);
    EXPECT_EQ(handler.asked(), (std::vector<int>{0, 1}));
    {
        std::lock_guard lock(mutex);
        ASSERT_EQ(refusals.size(), 1u);
        EXPECT_NE(refusals[0].find("over capacity: a test's capacity of 1"), std::string::npos)
            << refusals[0];
    }
    // The admitted one is still served.
    ASSERT_TRUE(first.sendFrameRequest(request(1)).ok());
    EXPECT_EQ(receive(first, 0, 1000, 4, 5s).streams, 4);
    // Its slot freed, the next headset is admitted.
    first.disconnect();
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (!server->clients().empty() && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(5ms);
    Client third(clientOptions());
    EXPECT_TRUE(third.connect("127.0.0.1", server->port()).ok()) << third.lastError().error();
}

// A server of another protocol version: the client names the reason and counts the refusal.
TEST(NetTransport, ClientNamesAServerOfAnotherVersion) {
    asio::io_context io;
    asio::ip::tcp::acceptor acceptor(io, {asio::ip::make_address("127.0.0.1"), 0});
    const uint16_t port = acceptor.local_endpoint().port();
    std::thread old_server([&] {
        asio::ip::tcp::socket s(io);
        acceptor.accept(s);
        std::array<uint8_t, kControlHeaderBytes> header{};
        asio::error_code ec;
        asio::read(s, asio::buffer(header), ec);
        auto bye = encodeControl(Bye{ByeReason::kProtocolError});
        bye[2] = 1;  // as a version-1 server would answer
        asio::write(s, asio::buffer(bye), ec);
        std::this_thread::sleep_for(200ms);
    });
    Client client(clientOptions());
    const Status st = client.connect("127.0.0.1", port);
    old_server.join();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().find("another protocol version"), std::string::npos) << st.error();
    EXPECT_EQ(client.stats().incompatible_refusals, 1u);
}

// Control after the handshake is sealed (docs/PROTOCOL.md §Sealed control): a message that is
// replayed, skips a counter, carries a flipped bit, was sealed with another key or comes plain
// is counted and ends the session, and never reaches the handler.
TEST(NetTransport, ForgedReplayedAndTamperedControlEndTheSessionUnheard) {
    EchoServer handler(1000);
    auto server = startServer(handler);
    const auto waitFor = [](auto done) {
        const auto deadline = std::chrono::steady_clock::now() + 2s;
        while (!done() && std::chrono::steady_clock::now() < deadline) {
            std::this_thread::sleep_for(2ms);
        }
    };
    {
        // An authentic request is served; the very same bytes again are a replay.
        RawPeer peer(server->port());
        auto welcome = peer.handshake(testKey());
        ASSERT_TRUE(welcome && std::holds_alternative<Welcome>(*welcome));
        const auto sealed = peer.seal(request(1));
        peer.send(sealed);
        waitFor([&] { return handler.requests.load() == 1; });
        ASSERT_EQ(handler.requests.load(), 1);
        peer.send(sealed);
        peer.sendSealed(request(2));  // authentic, but the stream is no longer trusted
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // counter 1 where 0 is due: a message was deleted
        ASSERT_TRUE(peer.handshake(testKey()).has_value());
        (void)peer.seal(request(3));
        peer.sendSealed(request(4));
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // one bit flipped in the ciphertext
        ASSERT_TRUE(peer.handshake(testKey()).has_value());
        auto flipped = peer.seal(request(5));
        flipped[kControlHeaderBytes + 8 + 20] ^= 0x04;
        peer.send(flipped);
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // sealed with a key of another session
        ASSERT_TRUE(peer.handshake(testKey()).has_value());
        const SessionKeys other = sessionKeys(testKey(), randomNonce(), randomNonce(), 99);
        peer.send(sealControl(request(6), other.client_to_server, 1));
        EXPECT_TRUE(peer.closedByPeer());
    }
    {
        RawPeer peer(server->port());  // plain, as an injector without the key would send it
        ASSERT_TRUE(peer.handshake(testKey()).has_value());
        peer.send(encodeControl(request(7)));
        EXPECT_TRUE(peer.closedByPeer());
    }
    waitFor([&] { return handler.gone.load() == 5; });
    const ServerStats st = server->stats();
    EXPECT_EQ(handler.requests.load(), 1);  // only the authentic first request was heard
    EXPECT_EQ(st.frame_requests, 1u);
    EXPECT_EQ(st.control_replayed, 2u);
    EXPECT_EQ(st.control_forged, 3u);
    EXPECT_EQ(st.control_drops[WireError::kReplayed], 2u);
    EXPECT_EQ(st.control_drops[WireError::kBadMac], 2u);
    EXPECT_EQ(st.control_drops[WireError::kUnsealed], 1u);
    EXPECT_EQ(st.clients_accepted, 5u);
    EXPECT_EQ(handler.gone.load(), 5);
    EXPECT_TRUE(server->clients().empty());
}

// Return routability (docs/PROTOCOL.md §Return routability): a key holder that names a UDP port
// it does not receive at (another process's port on its host), or never echoes the probe, or
// echoes a wrong token, gets no media and is refused with the reason, counted.
TEST(NetTransport, MediaGoesOnlyToAPortTheClientProvedItReceivesAt) {
    EchoServer handler(1000);
    ServerOptions o;
    o.route_probe_interval_ms = 50;
    o.route_probe_attempts = 3;
    auto server = startServer(handler, o);
    asio::io_context io;
    asio::ip::udp::socket victim(io, {asio::ip::make_address("127.0.0.1"), 0});
    {
        RawPeer peer(server->port());  // names the victim's port
        auto reply = peer.handshake(testKey(), victim.local_endpoint().port());
        ASSERT_TRUE(reply && std::holds_alternative<Bye>(*reply));
        EXPECT_EQ(std::get<Bye>(*reply).reason, ByeReason::kRouteUnverified);
        EXPECT_TRUE(peer.closedByPeer());
    }
    using Route = RawPeer::Route;
    for (const Route route : {Route::kSilent, Route::kWrongToken}) {
        RawPeer peer(server->port());  // receives the probe, then never answers or guesses
        auto reply = peer.handshake(testKey(), std::nullopt, route);
        ASSERT_TRUE(reply && std::holds_alternative<Bye>(*reply));
        EXPECT_EQ(std::get<Bye>(*reply).reason, ByeReason::kRouteUnverified);
    }
    {
        // Asking for a key frame before the check passed is a protocol error, not honoured.
        RawPeer peer(server->port());
        auto reply =
            peer.handshake(testKey(), victim.local_endpoint().port(), Route::kSomethingElse);
        ASSERT_TRUE(reply && std::holds_alternative<Bye>(*reply));
        EXPECT_EQ(std::get<Bye>(*reply).reason, ByeReason::kProtocolError);
    }
    // What reached the victim's port: probes only (3 for the first peer, the first of the
    // last peer's), never media.
    victim.non_blocking(true);
    std::array<uint8_t, 2048> buf{};
    int probes = 0, other = 0;
    for (;;) {
        asio::error_code ec;
        const size_t n = victim.receive(asio::buffer(buf), 0, ec);
        if (ec) {
            break;
        }
        (isRouteProbe(std::span<const uint8_t>(buf.data(), n)) ? probes : other) += 1;
    }
    EXPECT_EQ(other, 0);
    // (The last peer's request reaches the server before its second probe unless the machine
    // stalls the server for an interval.)
    EXPECT_GE(probes, 3 + 1);
    EXPECT_LE(probes, 3 + 3);
    const ServerStats st = server->stats();
    EXPECT_EQ(st.route_failures, 3u);
    EXPECT_EQ(st.protocol_errors, 1u);
    EXPECT_EQ(st.control_drops.total(), 0u);
    EXPECT_EQ(st.packets_sent, 0u);
    EXPECT_EQ(st.clients_accepted, 0u);
    EXPECT_EQ(handler.connected.load(), 0);
    EXPECT_EQ(handler.requests.load(), 0);
    // A client that does receive at its port gets in and is served as always.
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    ASSERT_TRUE(client.sendFrameRequest(request(1)).ok());
    const Received r = receive(client, 0, 1000, 4, 5s);
    EXPECT_EQ(r.streams, 4);
}

TEST(NetTransport, SilentPeerIsDroppedAfterTheHandshakeTimeout) {
    EchoServer handler(1000);
    ServerOptions o;
    o.handshake_timeout_ms = 150;
    auto server = startServer(handler, o);
    RawPeer peer(server->port());
    auto m = peer.read();  // blocks until the server gives up
    ASSERT_TRUE(m && std::holds_alternative<Bye>(*m));
    EXPECT_EQ(std::get<Bye>(*m).reason, ByeReason::kTimeout);
    EXPECT_EQ(server->stats().handshake_timeouts, 1u);
}

// A key holder's NACKs (issue 12 drew 29.5 MB with 210 KB of them): each sent datagram is resent
// at most twice however often it is named, and a session's retransmissions never exceed what it
// first sent, so NACKs can at most double what the server sends.
TEST(NetTransport, NackFloodDrawsAtMostTwiceTheMedia) {
    EchoServer handler(20 * 1200);  // 20 datagrams per stream and frame
    auto server = startServer(handler);
    RawPeer peer(server->port());
    auto welcome = peer.handshake(testKey());
    ASSERT_TRUE(welcome && std::holds_alternative<Welcome>(*welcome));
    asio::ip::udp::socket& media = peer.media();
    const auto drain = [&] {
        std::array<uint8_t, 2048> buf{};
        uint64_t bytes = 0;
        media.non_blocking(true);
        auto quiet_since = std::chrono::steady_clock::now();
        while (std::chrono::steady_clock::now() - quiet_since < 300ms) {
            asio::error_code ec;
            const size_t n = media.receive(asio::buffer(buf), 0, ec);
            if (ec) {
                std::this_thread::sleep_for(2ms);
                continue;
            }
            bytes += n;
            quiet_since = std::chrono::steady_clock::now();
        }
        return bytes;
    };
    for (uint32_t f = 1; f <= 10; ++f) {
        peer.sendSealed(request(f));
    }
    const uint64_t media_bytes = drain();
    ASSERT_GT(media_bytes, 10u * 4 * 20 * 1200);
    // 10,000 NACKs, each naming 64 sequence numbers the server still holds.
    uint64_t nack_bytes = 0;
    for (int i = 0; i < 10'000; ++i) {
        const auto nack =
            peer.seal(Nack{static_cast<uint8_t>(i % kMaxStreams),
                           static_cast<uint32_t>((i / kMaxStreams) % 3 * 64), ~uint64_t{0}});
        nack_bytes += nack.size();
        peer.send(nack);
    }
    const uint64_t drawn = drain();
    const ServerStats st = server->stats();
    std::printf(
        "%llu B of media, %llu B of NACKs drew %llu B (%llu packets resent, %llu "
        "refused)\n",
        static_cast<unsigned long long>(media_bytes), static_cast<unsigned long long>(nack_bytes),
        static_cast<unsigned long long>(drawn),
        static_cast<unsigned long long>(st.packets_retransmitted),
        static_cast<unsigned long long>(st.retransmissions_refused));
    EXPECT_GT(drawn, 0u);
    EXPECT_LE(drawn, media_bytes);  // at most as much again as was sent
    EXPECT_EQ(st.bytes_retransmitted, drawn);
    EXPECT_GT(st.retransmissions_refused, 0u);
    EXPECT_LE(media_bytes + drawn, 2 * media_bytes);
}

TEST(NetTransport, SilentAuthenticatedSessionIsEndedAfterTheIdleTimeout) {
    EchoServer handler(1000);
    ServerOptions o;
    o.idle_timeout_ms = 300;
    auto server = startServer(handler, o);
    // A client that keeps asking for frames stays.
    Client busy(clientOptions());
    ASSERT_TRUE(busy.connect("127.0.0.1", server->port()).ok());
    // One that authenticates and then says nothing (a stopped headset) is ended.
    RawPeer silent(server->port());
    auto welcome = silent.handshake(testKey());
    ASSERT_TRUE(welcome && std::holds_alternative<Welcome>(*welcome));
    const auto t0 = std::chrono::steady_clock::now();
    std::atomic<bool> done{false};
    std::thread keep([&] {
        for (uint32_t f = 1; !done; ++f) {
            (void)busy.sendFrameRequest(request(f));
            std::this_thread::sleep_for(50ms);
        }
    });
    auto m = silent.read();  // blocks until the server gives up on it
    const auto waited = std::chrono::steady_clock::now() - t0;
    ASSERT_TRUE(m && std::holds_alternative<Bye>(*m));
    EXPECT_EQ(std::get<Bye>(*m).reason, ByeReason::kTimeout);
    EXPECT_GE(waited, 250ms);
    std::this_thread::sleep_for(400ms);  // longer than the timeout: the busy one must stay
    done = true;
    keep.join();
    EXPECT_TRUE(busy.connected());
    EXPECT_EQ(server->stats().idle_timeouts, 1u);
    EXPECT_EQ(server->clients().size(), 1u);
}

TEST(NetTransport, AClientWithNothingToAskKeepsItsSessionWithKeepAlives) {
    // A headset that renders everything itself for a while requests nothing and receives no
    // media to acknowledge. Before KeepAlive the server's idle timeout ended its session
    // (a 10-minute qvr run at 5% loss: 7 sessions ended, 7 reconnects).
    EchoServer handler(1000);
    ServerOptions o;
    o.idle_timeout_ms = 300;
    auto server = startServer(handler, o);
    ClientOptions co = clientOptions();
    co.keepalive_ms = 100;
    Client quiet(co);
    ASSERT_TRUE(quiet.connect("127.0.0.1", server->port()).ok());
    std::this_thread::sleep_for(1200ms);  // four idle timeouts
    EXPECT_TRUE(quiet.connected());
    EXPECT_EQ(server->stats().idle_timeouts, 0u);
    EXPECT_GE(server->stats().keepalives, 5u);
    EXPECT_GE(quiet.stats().keepalives_sent, 5u);
    // Without them it is ended, as a stopped client should be.
    co.keepalive_ms = 0;
    Client mute(co);
    ASSERT_TRUE(mute.connect("127.0.0.1", server->port()).ok());
    std::this_thread::sleep_for(1200ms);
    EXPECT_FALSE(mute.connected());
    EXPECT_EQ(server->stats().idle_timeouts, 1u);
}

// Attackers without the key (issue 12): `per_thread` connections per thread, each from the
// thread's own source address, that send a valid ClientHello and then nothing, reopened as soon
// as the server drops one. Plain sockets and poll, so a thread watches all its connections.
class HandshakeFlood {
public:
    HandshakeFlood(uint16_t port, int threads, int per_thread, int first_source) {
        for (int t = 0; t < threads; ++t) {
            m_threads.emplace_back([this, port, per_thread, source = first_source + t] {
                run(port, per_thread, source);
            });
        }
    }
    ~HandshakeFlood() {
        m_stop = true;
        for (auto& t : m_threads) {
            t.join();
        }
    }
    std::atomic<int64_t> opened{0};
    std::atomic<int64_t> open_now{0};

private:
    void run(uint16_t port, int n, int source) {
        const std::string hello_host = "127.0.0." + std::to_string(source);
        const std::vector<uint8_t> hello = encodeControl(ClientHello{randomNonce(), 40000});
        std::vector<pollfd> fds(static_cast<size_t>(n), pollfd{-1, POLLIN, 0});
        std::array<uint8_t, 512> buf{};
        while (!m_stop) {
            for (auto& p : fds) {
                if (p.fd >= 0) {
                    continue;
                }
                const int fd = socket(AF_INET, SOCK_STREAM, 0);
                sockaddr_in from{};
                from.sin_family = AF_INET;
                inet_pton(AF_INET, hello_host.c_str(), &from.sin_addr);
                sockaddr_in to{};
                to.sin_family = AF_INET;
                to.sin_port = htons(port);
                inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
                if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof from) != 0 ||
                    connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0 ||
                    send(fd, hello.data(), hello.size(), MSG_NOSIGNAL) !=
                        static_cast<ssize_t>(hello.size())) {
                    if (fd >= 0) {
                        close(fd);
                    }
                    std::this_thread::sleep_for(1ms);
                    continue;
                }
                p.fd = fd;
                ++opened;
                ++open_now;
            }
            if (poll(fds.data(), fds.size(), 20) <= 0) {
                continue;
            }
            for (auto& p : fds) {
                if (p.fd < 0 || !(p.revents & (POLLIN | POLLHUP | POLLERR))) {
                    continue;
                }
                // The challenge (kept, then silence) or the server hanging up (reopen).
                const ssize_t got = recv(p.fd, buf.data(), buf.size(), MSG_DONTWAIT);
                if (got <= 0) {
                    close(p.fd);
                    p.fd = -1;
                    --open_now;
                }
            }
        }
        for (auto& p : fds) {
            if (p.fd >= 0) {
                close(p.fd);
            }
        }
    }

    std::atomic<bool> m_stop{false};
    std::vector<std::thread> m_threads;
};

// Under the flood of issue 12 (16 silent unauthenticated connections, reopened as dropped) and
// one ten times harder (160, from ten other source addresses), and one beyond the server's
// limits, a client with the key still
// connects within 1 s in at least 99 of 100 attempts, and a session that runs through the flood
// keeps receiving its frames.
TEST(NetTransport, KeyHoldersGetInDuringAPreAuthFlood) {
    struct Level {
        int threads, per_thread, first_source;
    };
    // The third: 400 from four addresses, beyond the per-source and total limits, so the server
    // evicts (each flooding source churns its own slots).
    for (const Level level : {Level{1, 16, 1}, Level{10, 16, 2}, Level{4, 100, 20}}) {
        EchoServer handler(3000);
        auto server = startServer(handler);
        Client running(clientOptions());
        ASSERT_TRUE(running.connect("127.0.0.1", server->port()).ok());
        HandshakeFlood flood(server->port(), level.threads, level.per_thread, level.first_source);
        const int attackers = level.threads * level.per_thread;
        const auto settle = std::chrono::steady_clock::now() + 3s;
        while (flood.open_now.load() < attackers && std::chrono::steady_clock::now() < settle) {
            std::this_thread::sleep_for(10ms);
        }
        EXPECT_GE(flood.open_now.load(), attackers * 9 / 10) << "the flood did not build up";
        int connected = 0;
        int frames_asked = 0;
        uint32_t frame = 1;
        Received got;
        for (int attempt = 0; attempt < 100; ++attempt) {
            ClientOptions o = clientOptions();
            o.connect_timeout_ms = 1000;
            Client c(o);
            connected += c.connect("127.0.0.1", server->port()).ok() ? 1 : 0;
            c.disconnect();
            // Meanwhile the running session asks for a frame and takes what came.
            if (running.sendFrameRequest(request(frame++)).ok()) {
                ++frames_asked;
            }
            const Received r = receive(running, 0, 3000, kMaxStreams, 100ms);
            got.streams += r.streams;
        }
        const Received tail = receive(running, 0, 3000, kMaxStreams * frames_asked, 1s);
        got.streams += tail.streams;
        const ServerStats st = server->stats();
        std::printf(
            "flood of %d: %d/100 connected within 1 s, %d/%d streams to the running "
            "session, %lld attacker connections opened, %llu evicted, %llu timed out\n",
            attackers, connected, got.streams, kMaxStreams * frames_asked,
            static_cast<long long>(flood.opened.load()),
            static_cast<unsigned long long>(st.pending_evicted),
            static_cast<unsigned long long>(st.handshake_timeouts));
        EXPECT_GE(connected, 99) << attackers;
        EXPECT_TRUE(running.connected());
        EXPECT_EQ(frames_asked, 100);
        EXPECT_GE(got.streams, kMaxStreams * frames_asked * 95 / 100) << attackers;
    }
}

TEST(NetTransport, ServesSeveralClientsAndRefusesBeyondTheLimit) {
    EchoServer handler(5000);
    ServerOptions o;
    o.max_clients = 3;
    auto server = startServer(handler, o);
    std::vector<std::unique_ptr<Client>> clients;
    for (int i = 0; i < 3; ++i) {
        clients.push_back(std::make_unique<Client>(clientOptions()));
        ASSERT_TRUE(clients.back()->connect("127.0.0.1", server->port()).ok());
    }
    Client fourth(clientOptions());
    const Status full = fourth.connect("127.0.0.1", server->port());
    ASSERT_FALSE(full.ok());
    EXPECT_NE(full.error().find("full"), std::string::npos) << full.error();
    EXPECT_EQ(server->stats().refused_full, 1u);
    for (auto& c : clients) {
        for (uint32_t f = 1; f <= 10; ++f) {
            ASSERT_TRUE(c->sendFrameRequest(request(f)).ok());
        }
    }
    for (auto& c : clients) {
        // Each client receives its own 40 streams (content is keyed by its session id, checked
        // below by counting: a stream meant for another client would not reach this socket).
        const Received r = receive(*c, 0, 5000, 40, 5s);
        EXPECT_EQ(r.streams, 40);
        EXPECT_EQ(r.per_frame.size(), 10u);
    }
    EXPECT_EQ(server->clients().size(), 3u);
}

TEST(NetTransport, FivePercentLossKeepsFramesComingWithKeyFrameRequests) {
    EchoServer handler(4 * kMediaChunkBytes);  // 4 packets per stream: P(complete) = 0.95^4
    ServerOptions o;
    auto link = parseLinkSpec("wifi,loss=0.05,seed=5");
    ASSERT_TRUE(link) << link.error();
    o.link = link.value();
    o.fec.enabled = false;  // key frames alone; FEC: FecAloneCompletesStreamsAtFivePercentLoss
    auto server = startServer(handler, o);
    ClientOptions co = clientOptions();
    co.retransmit = false;  // this test is about recovery by key frames alone
    co.key_frame_retry_ms = 5;
    co.assembler.frame_timeout_ns = 30'000'000;
    Client client(co);
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    const ClientId id = server->clients()[0];
    const int frames = 300;
    Received total;
    std::map<uint32_t, int> decodable_last_quarter;
    for (uint32_t f = 1; f <= frames; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
        std::this_thread::sleep_for(2ms);  // a 500 Hz client: losses reach the server in time
        while (true) {
            auto s = client.nextStream(0);
            ASSERT_TRUE(s.ok()) << s.error();
            if (!s->has_value()) {
                break;
            }
            ++total.streams;
            total.decodable += (*s)->decodable ? 1 : 0;
            total.corrupt += (*s)->bytes !=
                             streamBytes(id, (*s)->frame_id, (*s)->stream_id, 4 * kMediaChunkBytes);
            if ((*s)->frame_id > 3 * frames / 4 && (*s)->decodable) {
                ++decodable_last_quarter[(*s)->frame_id];
            }
        }
    }
    const Received tail = receive(client, id, 4 * kMediaChunkBytes, 1 << 20, 300ms);
    total.streams += tail.streams;
    total.decodable += tail.decodable;
    const LinkStats ls = server->linkStats(id);
    const ClientStats cs = client.stats();
    const double loss = static_cast<double>(ls.dropped_loss) / static_cast<double>(ls.packets_in);
    RecordProperty("streams_complete", total.streams);
    RecordProperty("streams_decodable", total.decodable);
    RecordProperty("key_frame_requests", static_cast<int>(cs.key_frame_requests_sent));
    EXPECT_NEAR(loss, 0.05, 0.02);
    EXPECT_EQ(total.corrupt, 0);
    // ≈ 0.95^4 = 81% of 1200 streams complete. A loss (18.5% of stream frames) leaves its
    // stream undecodable until a key frame arrives — detection at the next frame, the request,
    // the key frame a frame later, itself lost 18.5% of the time — so ~55% stay decodable.
    // Without key-frame requests a stream would never decode again after its first loss
    // (a few percent of 1200), so the bound below shows recovery, not luck.
    EXPECT_GT(total.streams, 1200 * 0.70);
    EXPECT_GT(total.decodable, 1200 * 0.35);
    EXPECT_GT(cs.assembler.streams_lost, 0u);
    EXPECT_FALSE(client.takeLost().empty());  // the caller learns which streams to stop awaiting
    EXPECT_GT(cs.key_frame_requests_sent, 10u);
    EXPECT_GT(handler.key_requests.load(), 10);
    EXPECT_GT(handler.key_frames_sent.load(), 10);
    EXPECT_GT(decodable_last_quarter.size(), 50u);  // still coming at the end
    // Every stream was accounted for: completed, or lost and acknowledged as lost.
    EXPECT_GE(cs.assembler.streams_completed + cs.assembler.streams_lost,
              static_cast<uint64_t>(total.streams));
}

// The same 5% loss and 4-packet streams as FivePercentLossKeepsFramesComingWithKeyFrameRequests,
// retransmission still off, but the server adds Reed-Solomon parity sized from the loss the
// client reports: once the first report arrived (256 sequence numbers), a stream frame is lost
// only when more than its m parity packets are (m = 2 at 5%: P = 0.2%). Without FEC that test
// completes ≈ 0.95^4 = 81% of the streams and keeps ~55% decodable.
TEST(NetTransport, FecAloneCompletesStreamsAtFivePercentLoss) {
    const size_t stream_bytes = 4 * kMediaChunkBytes;
    EchoServer handler(stream_bytes);
    ServerOptions o;
    o.link = parseLinkSpec("wifi,loss=0.05,seed=5").value();
    auto server = startServer(handler, o);
    ClientOptions co = clientOptions();
    co.retransmit = false;  // FEC alone
    co.key_frame_retry_ms = 5;
    co.assembler.frame_timeout_ns = 30'000'000;
    Client client(co);
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    const ClientId id = server->clients()[0];
    const int frames = 300;
    Received total;
    for (uint32_t f = 1; f <= frames; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
        std::this_thread::sleep_for(2ms);
        while (true) {
            auto s = client.nextStream(0);
            ASSERT_TRUE(s.ok()) << s.error();
            if (!s->has_value()) {
                break;
            }
            ++total.streams;
            total.decodable += (*s)->decodable ? 1 : 0;
            total.corrupt +=
                (*s)->bytes != streamBytes(id, (*s)->frame_id, (*s)->stream_id, stream_bytes);
        }
    }
    const Received tail = receive(client, id, stream_bytes, 1 << 20, 300ms);
    total.streams += tail.streams;
    total.decodable += tail.decodable;
    total.corrupt += tail.corrupt;
    const LinkStats ls = server->linkStats(id);
    const ClientStats cs = client.stats();
    const ServerStats ss = server->stats();
    // The server's total over its sessions' links (one session here), read in between.
    const LinkStats ls_after = server->linkStats(id);
    EXPECT_GE(ss.link.packets_in, ls.packets_in);
    EXPECT_LE(ss.link.packets_in, ls_after.packets_in);
    EXPECT_GE(ss.link.dropped_loss, ls.dropped_loss);
    EXPECT_LE(ss.link.dropped_loss, ls_after.dropped_loss);
    EXPECT_GT(ss.link.dropped_loss, 0u);
    const double loss = static_cast<double>(ls.dropped_loss) / static_cast<double>(ls.packets_in);
    RecordProperty("streams_complete", total.streams);
    RecordProperty("streams_decodable", total.decodable);
    RecordProperty("fec_recoveries", static_cast<int>(cs.assembler.fec_recoveries));
    RecordProperty("fec_parity_bytes", static_cast<int>(ss.fec_parity_bytes));
    RecordProperty("key_frame_requests", static_cast<int>(cs.key_frame_requests_sent));
    EXPECT_NEAR(loss, 0.05, 0.02);
    EXPECT_EQ(total.corrupt, 0);  // rebuilt bytes are the bytes sent
    EXPECT_NEAR(ss.client_loss_ppm, 50'000, 30'000);
    // Stated bound: ≥ 95% complete and ≥ 90% decodable (without FEC: > 70% and > 35%).
    EXPECT_GE(total.streams, 1200 * 95 / 100);
    EXPECT_GE(total.decodable, 1200 * 90 / 100);
    EXPECT_GT(cs.assembler.fec_recoveries, 50u);  // ≈ 18% of ~1100 stream frames lost a packet
    EXPECT_GE(cs.assembler.fec_packets_recovered, cs.assembler.fec_recoveries);
    EXPECT_GT(ss.fec_parity_packets, 1000u);
    EXPECT_GT(ss.fec_parity_bytes, ss.fec_parity_packets * kMediaChunkBytes);
    EXPECT_EQ(cs.assembler.fec_failures, 0u);
}

// With selective retransmission a frame of realistic size survives 5% loss: a 48 KB layer is
// 40 packets, complete without help only 0.95^40 = 13% of the time; one NACK round leaves a
// packet missing with probability 0.05² and two rounds 0.05³.
TEST(NetTransport, RetransmissionCompletesRealisticFramesAtFivePercentLoss) {
    const size_t stream_bytes = 40 * kMediaChunkBytes;
    EchoServer handler(stream_bytes);
    ServerOptions o;
    o.link = parseLinkSpec("wifi,delay_ms=2,loss=0.05,seed=9").value();
    o.fec.enabled = false;  // NACKs alone
    auto server = startServer(handler, o);
    Client client(clientOptions());  // retransmit is on by default
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    const ClientId id = server->clients()[0];
    const int frames = 60;
    Received total;
    for (uint32_t f = 1; f <= frames; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
        const Received r = receive(client, id, stream_bytes, 4, 150ms);
        total.streams += r.streams;
        total.decodable += r.decodable;
        total.corrupt += r.corrupt;
    }
    const Received tail = receive(client, id, stream_bytes, 1 << 20, 200ms);
    total.streams += tail.streams;
    total.decodable += tail.decodable;
    const ClientStats cs = client.stats();
    const ServerStats ss = server->stats();
    EXPECT_EQ(total.corrupt, 0);
    RecordProperty("streams_complete", total.streams);
    RecordProperty("streams_decodable", total.decodable);
    RecordProperty("packets_recovered", static_cast<int>(cs.assembler.packets_recovered));
    RecordProperty("packets_retransmitted", static_cast<int>(ss.packets_retransmitted));
    RecordProperty("key_frame_requests", static_cast<int>(cs.key_frame_requests_sent));
    EXPECT_GE(total.streams, frames * 4 * 95 / 100);
    EXPECT_GE(total.decodable, frames * 4 * 90 / 100);
    EXPECT_GT(cs.assembler.packets_recovered, 200u);  // ≈ 5% of 9600 packets
    EXPECT_GT(ss.packets_retransmitted, 200u);
    EXPECT_GT(ss.nacks, 0u);
}

// Retransmission must not reorder a stream: the codec admits a P frame only right after its
// predecessor (ReferenceTracker), so a frame recovered by a NACK after its successor completed
// used to break the chain and cost a key frame (issue 12: 4.7% of frames at 2% loss, all
// key-frame requests from this). Every stream comes out in frame order, and a frame marked
// decodable that is not a key frame directly follows the previous one.
TEST(NetTransport, RetransmissionKeepsEachStreamInOrder) {
    const size_t stream_bytes = 3 * kMediaChunkBytes;
    EchoServer handler(stream_bytes);
    ServerOptions o;
    o.link = parseLinkSpec("wifi,delay_ms=1,loss=0.05,seed=11").value();
    o.fec.enabled = false;  // NACKs alone: the reordering case
    auto server = startServer(handler, o);
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok()) << client.lastError().error();
    const int frames = 300;
    std::array<int64_t, kMaxStreams> last{-1, -1, -1, -1};
    int out_of_order = 0, chain_breaks = 0, streams = 0;
    const auto take = [&](int wait_ms) {
        while (true) {
            auto s = client.nextStream(wait_ms);
            ASSERT_TRUE(s.ok()) << s.error();
            if (!s->has_value()) {
                return;
            }
            const CompletedStream& cs = **s;
            ++streams;
            int64_t& prev = last[cs.stream_id];
            out_of_order += static_cast<int64_t>(cs.frame_id) <= prev ? 1 : 0;
            chain_breaks +=
                cs.decodable && !cs.key_frame && static_cast<int64_t>(cs.frame_id) != prev + 1 ? 1
                                                                                               : 0;
            prev = cs.frame_id;
        }
    };
    for (uint32_t f = 1; f <= frames; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
        std::this_thread::sleep_for(2ms);
        take(0);
    }
    take(300);
    const ClientStats cs = client.stats();
    RecordProperty("streams", streams);
    RecordProperty("streams_held", static_cast<int>(cs.assembler.streams_held));
    EXPECT_EQ(out_of_order, 0);
    EXPECT_EQ(chain_breaks, 0);
    EXPECT_GT(cs.assembler.packets_recovered, 50u);  // ≈ 5% of 3600 packets came by NACK
    EXPECT_GT(cs.assembler.streams_held, 0u);        // and some frames waited for them
    EXPECT_GE(streams, frames * 4 * 90 / 100);
}

TEST(NetTransport, KilledServerSurfacesAsErrorAndTheClientReconnects) {
    EchoServer first_handler(3000);
    auto server = startServer(first_handler);
    const uint16_t port = server->port();
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", port).ok());
    for (uint32_t f = 1; f <= 5; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
    }
    EXPECT_EQ(receive(client, 0, 3000, 20, 3s).streams, 20);

    server->stop();  // mid-stream: the client is still requesting
    server.reset();
    client.sendFrameRequest(request(6));  // may race with the close; either way no crash
    const auto deadline = std::chrono::steady_clock::now() + 3s;
    Status seen = Status::success();
    while (std::chrono::steady_clock::now() < deadline) {
        auto s = client.nextStream(50);
        if (!s.ok()) {
            seen = makeError(s.error());
            break;
        }
    }
    ASSERT_FALSE(seen.ok()) << "the client never noticed the server was gone";
    EXPECT_FALSE(client.connected());
    EXPECT_FALSE(client.lastError().ok());
    EXPECT_FALSE(client.sendFrameRequest(request(7)).ok());
    // Nobody listens now: connecting fails with a message, quickly.
    const Status refused = client.connect("127.0.0.1", port);
    EXPECT_FALSE(refused.ok());

    EchoServer second_handler(3000);
    ServerOptions o;
    o.port = port;
    auto second = startServer(second_handler, o);
    ASSERT_EQ(second->port(), port);
    ASSERT_TRUE(client.connect("127.0.0.1", port).ok()) << client.lastError().error();
    for (uint32_t f = 100; f < 105; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
    }
    const Received r = receive(client, second->clients()[0], 3000, 20, 3s);
    EXPECT_EQ(r.streams, 20);
    EXPECT_EQ(r.corrupt, 0);
    EXPECT_EQ(client.stats().connects, 2u);
    EXPECT_GE(client.stats().connect_failures, 1u);
}

// The same with a real process death: the server runs in a child process that gets SIGKILL
// mid-stream, so nothing in it says goodbye; the kernel closing its sockets is all the client
// sees. Then a new server takes the port and the client reconnects.
TEST(NetTransport, SigkilledServerProcessSurfacesAsErrorAndTheClientReconnects) {
    int pipe_fds[2];
    ASSERT_EQ(pipe(pipe_fds), 0);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // Child: serve until killed. Only async-signal-safe exits from here on.
        close(pipe_fds[0]);
        EchoServer handler(3000);
        ServerOptions o;
        o.key = testKey();
        auto server = Server::start(o, handler);
        uint16_t port = server ? (*server)->port() : 0;
        if (server) {
            handler.server = server->get();
        }
        if (write(pipe_fds[1], &port, sizeof(port)) != sizeof(port)) {
            _exit(2);
        }
        for (int i = 0; i < 100; ++i) {  // at most 10 s, should the parent die first
            std::this_thread::sleep_for(100ms);
        }
        _exit(0);
    }
    close(pipe_fds[1]);
    uint16_t port = 0;
    ASSERT_EQ(read(pipe_fds[0], &port, sizeof(port)), static_cast<ssize_t>(sizeof(port)));
    close(pipe_fds[0]);
    ASSERT_NE(port, 0);

    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", port).ok()) << client.lastError().error();
    for (uint32_t f = 1; f <= 5; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
    }
    EXPECT_EQ(receive(client, 0, 3000, 20, 3s).streams, 20);
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status));

    const auto deadline = std::chrono::steady_clock::now() + 3s;
    bool saw_error = false;
    while (!saw_error && std::chrono::steady_clock::now() < deadline) {
        saw_error = !client.nextStream(50).ok();
    }
    ASSERT_TRUE(saw_error) << "the client never noticed the server process died";
    EXPECT_FALSE(client.connected());

    EchoServer handler(3000);
    ServerOptions o;
    o.port = port;
    auto second = startServer(handler, o);
    ASSERT_TRUE(client.connect("127.0.0.1", port).ok()) << client.lastError().error();
    ASSERT_TRUE(client.sendFrameRequest(request(50)).ok());
    EXPECT_EQ(receive(client, second->clients()[0], 3000, 4, 3s).streams, 4);
}

// Plays the server by hand (challenge, probe of the claimed media port, sealed Welcome), so a
// test can send the client exactly the datagrams and control bytes it means.
struct FakeServer {
    asio::io_context io;
    asio::ip::tcp::acceptor acceptor{io, {asio::ip::make_address("127.0.0.1"), 0}};
    asio::ip::udp::socket media{io, {asio::ip::make_address("127.0.0.1"), 0}};
    asio::ip::tcp::socket peer{io};
    ClientHello hello;
    Nonce server_nonce = randomNonce();
    uint64_t session = 77;
    SessionKeys keys;
    uint64_t send_counter = 0;
    uint64_t read_counter = 0;

    uint16_t port() const { return acceptor.local_endpoint().port(); }
    // The next message from the client, opened if sealed.
    ControlMessage read() {
        std::vector<uint8_t> raw(kControlHeaderBytes);
        asio::read(peer, asio::buffer(raw));
        ControlHeader h;
        EXPECT_EQ(decodeControlHeader(raw, h), WireError::kNone);
        raw.resize(kControlHeaderBytes + h.payload_bytes);
        asio::read(peer, asio::buffer(raw.data() + kControlHeaderBytes, h.payload_bytes));
        ControlMessage m;
        EXPECT_EQ(h.type == ControlType::kSealed
                      ? openControl(raw, keys.client_to_server, read_counter, m)
                      : decodeControl(raw, m),
                  WireError::kNone);
        return m;
    }
    std::vector<uint8_t> seal(const ControlMessage& m) {
        return sealControl(m, keys.server_to_client, send_counter++);
    }
    void send(const std::vector<uint8_t>& bytes) { asio::write(peer, asio::buffer(bytes)); }
    void handshake() {
        acceptor.accept(peer);
        hello = std::get<ClientHello>(read());
        send(encodeControl(
            ServerChallenge{server_nonce, session,
                            serverProof(testKey(), hello.client_nonce, server_nonce, session)}));
        const auto auth = std::get<ClientAuth>(read());
        EXPECT_TRUE(macEqual(
            auth.client_proof,
            clientProof(testKey(), hello.client_nonce, server_nonce, session, hello.media_port)));
        keys = sessionKeys(testKey(), hello.client_nonce, server_nonce, session);
        const RouteToken token = randomRouteToken();
        media.send_to(asio::buffer(sealRouteProbe(session, 0, token, keys.route)),
                      {asio::ip::make_address("127.0.0.1"), hello.media_port});
        const auto echo = std::get<RouteConfirm>(read());
        EXPECT_TRUE(tokenEqual(echo.token, token));
        send(seal(Welcome{session, media.local_endpoint().port()}));
    }
};

// The test plays the server by hand, so it can send the client exactly the datagrams and
// control bytes it means: every malformed datagram is dropped and counted by reason, a valid
// stream still completes and is acknowledged, and a broken control stream ends the session.
TEST(NetTransport, ClientDropsAndCountsMalformedMedia) {
    FakeServer fake;
    Client client(clientOptions());
    Status connected = makeError("not run");
    std::thread connecting([&] { connected = client.connect("127.0.0.1", fake.port()); });
    fake.handshake();
    connecting.join();
    ASSERT_TRUE(connected.ok()) << connected.error();
    const auto readMessage = [&fake] { return fake.read(); };
    auto& media = fake.media;
    const ClientHello& hello = fake.hello;
    const Nonce& server_nonce = fake.server_nonce;
    const uint64_t session = fake.session;

    const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), hello.media_port);
    // The fake server knows the nonces, so it holds the session's media key, as the real one.
    const MediaKey key = mediaKey(testKey(), hello.client_nonce, server_nonce, session);
    const auto sealed = [&](std::vector<uint8_t> d) {
        sealMediaPacket(d, key);
        return d;
    };
    uint32_t seq = 0;
    const std::vector<uint8_t> bytes(1500, 0x42);
    auto packets = packetizeStream(session, seq, 9, 0, true, bytes);
    auto send = [&](std::vector<uint8_t> d) { media.send_to(asio::buffer(d), to); };
    auto edited = [&](size_t at, uint8_t value) {  // edited, then sealed: the MAC holds
        auto d = packets[0];
        d[at] = value;
        return sealed(d);
    };
    send({'n', 'o', 'p', 'e'});                                    // truncated
    send(edited(0, 'X'));                                          // bad magic
    send(edited(2, kProtocolVersion + 1));                         // wrong version
    send(edited(20, 9));                                           // bad stream id
    send(std::vector<uint8_t>(kMaxSealedDatagramBytes + 100, 0));  // oversized
    uint32_t other_seq = 0;
    send(sealed(packetizeStream(session + 1, other_seq, 9, 0, true, bytes)[0]));  // other session
    // Forged and tampered: never reach the assembler (issue 12: 400 forged datagrams with the
    // right session id used to end the session).
    send(packets[0]);  // unsealed, as before version 2: its last 16 bytes are not a tag
    {
        auto forged = sealed(packets[0]);
        forged.back() ^= 0x01;  // the tag
        send(forged);
        auto flipped = sealed(packets[0]);
        flipped[kMediaHeaderBytes + 7] ^= 0x80;  // a payload bit
        send(flipped);
        auto header_flipped = sealed(packets[0]);
        header_flipped[24] ^= 0x01;  // packet_count, in clear but authenticated
        send(header_flipped);
        const MediaKey wrong = mediaKey(PresharedKey::fromPassphrase("other").value(),
                                        hello.client_nonce, server_nonce, session);
        auto other_key = packets[0];
        sealMediaPacket(other_key, wrong);
        send(other_key);
    }
    for (const auto& p : packets) {
        send(sealed(p));
    }
    auto s = client.nextStream(2000);
    ASSERT_TRUE(s.ok() && s->has_value());
    EXPECT_EQ((*s)->bytes, bytes);
    EXPECT_TRUE((*s)->decodable);
    const auto ack = std::get<MediaAck>(readMessage());
    EXPECT_EQ(ack.frame_id, 9u);
    EXPECT_TRUE(ack.complete);
    EXPECT_EQ(ack.bytes_received, 1500u);
    EXPECT_EQ(ack.packets_received, 2);
    const DropCounters drops = client.stats().media_drops;
    EXPECT_EQ(drops[WireError::kTruncated], 1u);
    EXPECT_EQ(drops[WireError::kBadMagic], 1u);
    EXPECT_EQ(drops[WireError::kWrongVersion], 1u);
    EXPECT_EQ(drops[WireError::kBadField], 1u);
    EXPECT_EQ(drops[WireError::kOversized], 1u);
    EXPECT_EQ(drops[WireError::kWrongSession], 1u);
    EXPECT_EQ(drops[WireError::kBadMac], 5u);
    // Replayed: an authentic datagram sent again, after its frame completed and while one is
    // being assembled; neither reaches the assembler, the session stays.
    send(sealed(packets[0]));
    auto next = packetizeStream(session, seq, 10, 0, false, bytes);
    send(sealed(next[0]));
    send(sealed(next[0]));
    send(sealed(next[1]));
    auto s2 = client.nextStream(2000);
    ASSERT_TRUE(s2.ok() && s2->has_value());
    EXPECT_EQ((*s2)->frame_id, 10u);
    (void)readMessage();  // its ack
    EXPECT_EQ(client.stats().media_drops[WireError::kReplayed], 2u);
    EXPECT_TRUE(client.connected());

    fake.send(fake.seal(ThroughputReport{123'000'000, 1}));
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (client.throughputBps() == 0 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(2ms);
    }
    EXPECT_EQ(client.throughputBps(), 123e6);
    // A control header that is not qvr: the client cannot re-frame the stream and hangs up.
    fake.send(std::vector<uint8_t>{'H', 'T', 'T', 'P', '/', '1', '.', '1'});
    auto gone = client.nextStream(2000);
    ASSERT_FALSE(gone.ok());
    EXPECT_NE(gone.error().find("protocol error"), std::string::npos) << gone.error();
    EXPECT_EQ(client.stats().control_drops[WireError::kBadMagic], 1u);
}

// The client side of sealed control: a server message replayed, bit-flipped or sent plain is
// counted, never acted on, and ends the connection (the caller reconnects).
TEST(NetTransport, ClientEndsAConnectionWhoseControlStreamWasTampered) {
    Client client(clientOptions());
    struct Case {
        const char* what;
        uint64_t forged, replayed;
    };
    const Case cases[] = {{"replayed", 0, 1}, {"flipped", 1, 1}, {"plain", 2, 1}};
    for (const Case& c : cases) {
        FakeServer fake;
        Status connected = makeError("not run");
        std::thread connecting([&] { connected = client.connect("127.0.0.1", fake.port()); });
        fake.handshake();
        connecting.join();
        ASSERT_TRUE(connected.ok()) << connected.error();
        const auto report = fake.seal(ThroughputReport{1'000'000, 1});
        fake.send(report);
        const auto deadline = std::chrono::steady_clock::now() + 2s;
        while (client.throughputBps() == 0 && std::chrono::steady_clock::now() < deadline) {
            std::this_thread::sleep_for(2ms);
        }
        ASSERT_EQ(client.throughputBps(), 1e6) << c.what;
        if (std::string_view(c.what) == "replayed") {
            fake.send(report);
        } else if (std::string_view(c.what) == "flipped") {
            auto flipped = fake.seal(ThroughputReport{2'000'000, 2});
            flipped[kControlHeaderBytes + 8 + 3] ^= 0x10;
            fake.send(flipped);
        } else {
            fake.send(encodeControl(ThroughputReport{3'000'000, 3}));
        }
        auto gone = client.nextStream(2000);
        ASSERT_FALSE(gone.ok()) << c.what;
        EXPECT_NE(gone.error().find("protocol error"), std::string::npos) << gone.error();
        EXPECT_EQ(client.throughputBps(), 1e6) << c.what;  // nothing forged was believed
        EXPECT_EQ(client.stats().control_forged, c.forged) << c.what;
        EXPECT_EQ(client.stats().control_replayed, c.replayed) << c.what;
    }
    const DropCounters drops = client.stats().control_drops;
    EXPECT_EQ(drops[WireError::kReplayed], 1u);
    EXPECT_EQ(drops[WireError::kBadMac], 1u);
    EXPECT_EQ(drops[WireError::kUnsealed], 1u);
}

TEST(NetTransport, ConnectTimesOutOnASilentServer) {
    // A listener that accepts and never answers: the handshake deadline ends the wait.
    asio::io_context io;
    asio::ip::tcp::acceptor acceptor(io, {asio::ip::make_address("127.0.0.1"), 0});
    ClientOptions o = clientOptions();
    o.connect_timeout_ms = 200;
    Client client(o);
    const auto start = std::chrono::steady_clock::now();
    const Status s = client.connect("127.0.0.1", acceptor.local_endpoint().port());
    const auto took = std::chrono::steady_clock::now() - start;
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().find("timed out"), std::string::npos) << s.error();
    EXPECT_LT(took, 2s);
}

TEST(NetTransport, ThroughputFromAcksTracksAShapedLink) {
    EchoServer handler(60'000);  // 240 KB per frame
    ServerOptions o;
    o.link = parseLinkSpec("rate:50").value();
    auto server = startServer(handler, o);
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok());
    const ClientId id = server->clients()[0];
    for (uint32_t f = 1; f <= 8; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
        EXPECT_EQ(receive(client, id, 60'000, 4, 3s).streams, 4);  // one frame at a time
    }
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (server->throughputBps(id) == 0 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(5ms);
    }
    // 240 KB + headers at 50 Mbit/s take ~40 ms; ack and scheduling delays only lower it (the
    // lower bound leaves room for a loaded machine: 2 cores shared by many builds).
    const double mbps = server->throughputBps(id) / 1e6;
    EXPECT_GT(mbps, 25.0);
    EXPECT_LT(mbps, 52.0);
}

TEST(NetTransport, ServesFramesOverATraceDrivenLinkWithDelayAndJitter) {
    const std::string spec = "trace:" + std::string(QVR_SHARED_DIR) +
                             "/data/network/TMobile-LTE-short.down@100,delay_ms=10,jitter_ms=3";
    auto link = loadLinkSpec(spec);
    ASSERT_TRUE(link) << link.error();
    // The fastest the link can carry the 40 streams: all datagrams queued at its first instant
    // (later sends only lose opportunities), plus the smallest delay, 10 − 3 ms.
    int64_t fastest_ns = 0;
    {
        LinkSpec bare = link.value();
        bare.delay_ms = bare.jitter_ms = 0;
        LinkEmulator model(bare);
        uint32_t seq = 0;
        for (int s = 0; s < 40; ++s) {
            for (auto& p : packetizeStream(1, seq, 1, 0, true, std::vector<uint8_t>(20'000))) {
                ASSERT_TRUE(model.send(std::move(p), 0));
            }
        }
        std::vector<std::vector<uint8_t>> out;
        while (auto next = model.nextDeliveryNs()) {
            fastest_ns = *next;
            model.deliver(*next, out);
        }
        fastest_ns += 7'000'000;
    }
    EchoServer handler(20'000);
    ServerOptions o;
    o.link = link.value();
    auto server = startServer(handler, o);
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok());
    const ClientId id = server->clients()[0];
    const auto start = std::chrono::steady_clock::now();
    for (uint32_t f = 1; f <= 10; ++f) {
        ASSERT_TRUE(client.sendFrameRequest(request(f)).ok());
    }
    const Received r = receive(client, id, 20'000, 40, 5s);
    const auto took = std::chrono::steady_clock::now() - start;
    EXPECT_EQ(r.streams, 40);
    EXPECT_EQ(r.corrupt, 0);
    EXPECT_GT(fastest_ns, 7'000'000 + 20'000'000);  // 820 KB at ~100 Mbit/s: tens of ms
    EXPECT_GE(took, std::chrono::nanoseconds(fastest_ns) - 1ms);  // the link really shaped it
    EXPECT_EQ(server->linkStats(id).dropped_loss, 0u);
}

TEST(NetTransport, SendStreamRejectsBadArgumentsAndUnknownClients) {
    EchoServer handler(1000);
    auto server = startServer(handler);
    EXPECT_FALSE(server->sendStream(12345, 1, 0, true, std::vector<uint8_t>(10)).ok());
    EXPECT_FALSE(server->sendStream(12345, 1, kMaxStreams, true, std::vector<uint8_t>(10)).ok());
    EXPECT_FALSE(server->sendStream(12345, 1, 0, true, {}).ok());
    EXPECT_FALSE(
        server->sendStream(12345, 1, 0, true, std::vector<uint8_t>(kMaxStreamFrameBytes + 1)).ok());
    ServerOptions bad;
    bad.bind_address = "not-an-address";
    auto s = Server::start(bad, handler);
    EXPECT_FALSE(s);
}

TEST(NetTransport, SlowLinkQueueIsBounded) {
    EchoServer handler(200'000);  // 800 KB per frame into a 1 Mbit/s link with a 64 KB queue
    ServerOptions o;
    o.link = parseLinkSpec("rate:1,queue_kb=64").value();
    auto server = startServer(handler, o);
    Client client(clientOptions());
    ASSERT_TRUE(client.connect("127.0.0.1", server->port()).ok());
    const ClientId id = server->clients()[0];
    ASSERT_TRUE(client.sendFrameRequest(request(1)).ok());
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (server->linkStats(id).packets_in < 600 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(5ms);
    }
    const LinkStats ls = server->linkStats(id);
    EXPECT_GT(ls.dropped_queue, 500u);
    EXPECT_LE((ls.packets_in - ls.dropped_queue) * kMaxDatagramBytes, 64u * 1024 + 20'000);
}

}  // namespace
}  // namespace qvr::net
