// Reading and writing control messages on a TCP stream with asio: the header is checked before
// the payload is read, and the payload lands in a fixed buffer of the protocol's maximum size,
// so no length a peer sends ever decides an allocation.
#pragma once

#include <netinet/tcp.h>
#include <asio.hpp>
#include <deque>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "qvr/net/protocol.h"

namespace qvr::net::detail {

// TCP keepalive probing after 1 s of silence, every 1 s, 3 tries: a peer whose host vanished
// without closing the connection is noticed in ~4 s (a crashed process is noticed at once: its
// kernel closes the socket). Best effort; errors leave the defaults.
inline void enableKeepAlive(asio::ip::tcp::socket& socket) {
    asio::error_code ec;
    socket.set_option(asio::socket_base::keep_alive(true), ec);
#if defined(TCP_KEEPIDLE) && defined(TCP_KEEPINTVL) && defined(TCP_KEEPCNT)
    socket.set_option(asio::detail::socket_option::integer<IPPROTO_TCP, TCP_KEEPIDLE>(1), ec);
    socket.set_option(asio::detail::socket_option::integer<IPPROTO_TCP, TCP_KEEPINTVL>(1), ec);
    socket.set_option(asio::detail::socket_option::integer<IPPROTO_TCP, TCP_KEEPCNT>(3), ec);
#endif
}

struct ReadResult {
    asio::error_code ec;  // the socket failed or closed
    WireError error = WireError::kNone;
    // A bad header, or (once sealed) a message that fails its tag or counter: the byte stream
    // cannot be re-synchronised, or can no longer be trusted.
    bool stream_broken = false;
    bool sealed = false;  // the message came sealed (and opened with the expected counter)
    ControlMessage message;
};

// Sealing of outgoing control messages once the session keys exist (docs/PROTOCOL.md §Sealed
// control): plain before, sealed with the next counter after.
struct ControlSealer {
    bool on = false;
    ControlKey key{};
    uint64_t next = 0;
    void start(const ControlKey& k) {
        on = true;
        key = k;
        next = 0;
    }
    std::vector<uint8_t> encode(const ControlMessage& m) {
        return on ? sealControl(m, key, next++) : encodeControl(m);
    }
};

class ControlReader {
public:
    // From now on sealed messages are opened with this key, counting from 0. Plain ones are still
    // decoded (ReadResult::sealed says which): the owner decides whether it accepts them.
    void seal(const ControlKey& key) {
        m_sealed = true;
        m_key = key;
        m_next = 0;
    }

    // handler(ReadResult). The reader and socket must outlive the operation.
    template <typename Handler>
    void read(asio::ip::tcp::socket& socket, Handler handler) {
        asio::async_read(
            socket, asio::buffer(m_buffer.data(), kControlHeaderBytes),
            [this, &socket, handler = std::move(handler)](const asio::error_code& ec,
                                                          size_t) mutable {
                if (ec) {
                    handler(ReadResult{ec, WireError::kNone, true, false, {}});
                    return;
                }
                ControlHeader header;
                WireError e = decodeControlHeader(
                    std::span<const uint8_t>(m_buffer.data(), kControlHeaderBytes), header);
                if (e == WireError::kNone && header.type == ControlType::kSealed && !m_sealed) {
                    e = WireError::kUnknownType;  // nothing to open it with yet
                }
                if (e != WireError::kNone) {
                    handler(ReadResult{{}, e, true, false, {}});
                    return;
                }
                readPayload(socket, header, std::move(handler));
            });
    }

private:
    template <typename Handler>
    void readPayload(asio::ip::tcp::socket& socket, ControlHeader header, Handler handler) {
        // decodeControlHeader bounded payload_bytes by kMaxControlPayloadBytes.
        asio::async_read(
            socket, asio::buffer(m_buffer.data() + kControlHeaderBytes, header.payload_bytes),
            [this, header, handler = std::move(handler)](const asio::error_code& ec,
                                                         size_t) mutable {
                if (ec) {
                    handler(ReadResult{ec, WireError::kNone, true, false, {}});
                    return;
                }
                ReadResult r;
                if (header.type == ControlType::kSealed) {
                    r.error = openControl(
                        std::span<const uint8_t>(m_buffer.data(),
                                                 kControlHeaderBytes + header.payload_bytes),
                        m_key, m_next, r.message);
                    // A forged or out-of-order message ends the trust in the stream.
                    r.stream_broken =
                        r.error == WireError::kBadMac || r.error == WireError::kReplayed;
                    r.sealed = !r.stream_broken;
                } else {
                    r.error = decodeControlPayload(
                        header.type,
                        std::span<const uint8_t>(m_buffer.data() + kControlHeaderBytes,
                                                 header.payload_bytes),
                        r.message);
                }
                handler(std::move(r));
            });
    }

    std::array<uint8_t, kControlHeaderBytes + kMaxControlPayloadBytes> m_buffer{};
    bool m_sealed = false;
    ControlKey m_key{};
    uint64_t m_next = 0;
};

// A bounded queue of outgoing messages with one write in flight at a time. One error handler
// for the whole queue, set by the owner: a write can complete after the code that queued it
// has moved on (the handshake), so per-message callbacks could outlive what they refer to.
class ControlWriter {
public:
    using ErrorHandler = std::function<void(const asio::error_code&)>;
    explicit ControlWriter(size_t max_queued) : m_max_queued(max_queued) {}

    void setErrorHandler(ErrorHandler on_error) { m_on_error = std::move(on_error); }
    // False when the queue is full (the peer stopped reading).
    bool push(asio::ip::tcp::socket& socket, std::vector<uint8_t> bytes) {
        if (m_queue.size() >= m_max_queued) {
            return false;
        }
        m_queue.push_back(std::move(bytes));
        if (!m_busy) {
            writeNext(socket);
        }
        return true;
    }
    void clear() {
        m_queue.clear();
        m_busy = false;
    }
    // Nothing queued or being written: a direct write cannot interleave with a queued one.
    bool idle() const { return !m_busy && m_queue.empty(); }

private:
    void writeNext(asio::ip::tcp::socket& socket) {
        if (m_queue.empty()) {
            m_busy = false;
            return;
        }
        m_busy = true;
        asio::async_write(socket, asio::buffer(m_queue.front()),
                          [this, &socket](const asio::error_code& ec, size_t) {
                              if (ec) {
                                  m_busy = false;
                                  if (ec != asio::error::operation_aborted && m_on_error) {
                                      m_on_error(ec);
                                  }
                                  return;
                              }
                              if (!m_queue.empty()) {
                                  m_queue.pop_front();
                              }
                              writeNext(socket);
                          });
    }

    size_t m_max_queued;
    std::deque<std::vector<uint8_t>> m_queue;
    bool m_busy = false;
    ErrorHandler m_on_error;
};

}  // namespace qvr::net::detail
