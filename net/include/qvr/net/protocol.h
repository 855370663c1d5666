// The qvr wire protocol (paper §3.2: parallel streams of the middle and outer layers per eye,
// plus a control channel). Pure encode/decode between bytes and structs; every byte is hostile.
// Byte layouts, limits and versioning: docs/PROTOCOL.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "qvr/core/pose.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr::net {

// 2: the ClientHello carries the session settings (codec, display profile) and the server
// refuses a mismatch with a named Bye reason.
// 3: forward error correction — the media header's fec_parity byte and parity flag, the
// MediaAck's loss_ppm.
// 4: every control message after the handshake is sealed (ChaCha20-Poly1305, a key per
// direction, a message counter as nonce), and the server checks that the client receives at its
// media port (a sealed UDP probe echoed back) before it sends any media there.
// 6: Bye(over capacity) — the server refuses a headset it cannot serve at its frame-rate floor.
// 7: a stream's frame header (codec FrameHeader version 2) says the server's time on the frame.
inline constexpr uint8_t kProtocolVersion = 7;

// Limits a decoder enforces before it trusts any length a peer sent.
inline constexpr size_t kControlHeaderBytes = 8;
inline constexpr size_t kMaxControlPayloadBytes = 1024;  // the largest message is ~270 bytes
inline constexpr size_t kMediaHeaderBytes = 32;
inline constexpr size_t kMediaChunkBytes = 1200;  // payload per packet; fits a 1280-byte IPv6 MTU
inline constexpr size_t kMaxDatagramBytes = kMediaHeaderBytes + kMediaChunkBytes;
inline constexpr uint32_t kMaxPacketsPerFrame = 4096;  // ≤ 4.9 MB per layer and frame
inline constexpr uint32_t kMaxStreamFrameBytes = kMaxPacketsPerFrame * kMediaChunkBytes;
inline constexpr int kMaxStreams = 4;                // eye × {middle, outer}
inline constexpr int32_t kMaxImageExtentPx = 16384;  // rectangle coordinates and framebuffer sizes
inline constexpr size_t kNonceBytes = 32;
inline constexpr size_t kMacBytes = 32;
inline constexpr size_t kSettingNameBytes = 16;
// Media datagrams are sealed (docs/PROTOCOL.md §Sealed media): a 16-byte Poly1305 tag follows.
inline constexpr size_t kMediaTagBytes = 16;
inline constexpr size_t kMaxSealedDatagramBytes = kMaxDatagramBytes + kMediaTagBytes;
inline constexpr size_t kMediaKeyBytes = 32;
using MediaKey = std::array<uint8_t, kMediaKeyBytes>;
// Sealed control (docs/PROTOCOL.md §Sealed control): counter u64 ‖ ciphertext of (inner type ‖
// inner payload) ‖ 16-byte tag, inside a control header of type kSealed.
using ControlKey = std::array<uint8_t, kMediaKeyBytes>;
inline constexpr size_t kControlTagBytes = 16;
inline constexpr size_t kSealedControlOverhead = 8 + 1 + kControlTagBytes;
// Return routability (docs/PROTOCOL.md §Return routability): a random token the server seals
// into a UDP probe to the client's claimed media port and the client echoes over control.
inline constexpr size_t kRouteTokenBytes = 16;
using RouteToken = std::array<uint8_t, kRouteTokenBytes>;
inline constexpr size_t kRouteProbeHeaderBytes = 12;
inline constexpr size_t kRouteProbeBytes = kRouteProbeHeaderBytes + kRouteTokenBytes + 16;

// Stream id = 2·eye + layer: the four parallel streams of Fig. 7.
enum class Layer : uint8_t { kMiddle = 0, kOuter = 1 };
constexpr uint8_t streamId(int eye, Layer layer) {
    return static_cast<uint8_t>(2 * eye + static_cast<int>(layer));
}

// Why a message was dropped; each has a counter (DropCounters).
enum class WireError : uint8_t {
    kNone = 0,
    kTruncated,      // shorter than its header or its declared length
    kOversized,      // a length field above the protocol limit
    kBadMagic,       // not a qvr message at all
    kWrongVersion,   // a qvr message of another protocol version
    kUnknownType,    // a message type this version does not define
    kBadField,       // a field out of its range (NaN pose, rect outside the image, ...)
    kTrailingBytes,  // more bytes than the type's fixed layout
    kBadMac,         // handshake proof that does not verify
    kWrongSession,   // media of another session
    kReplayed,       // sealed media seen before, or older than the replay window; sealed
                     // control whose counter is not the next one (replayed, reordered, deleted)
    kUnsealed,       // a plain control message where only sealed ones are allowed
};
inline constexpr int kWireErrorCount = 12;
std::string_view wireErrorName(WireError e);

struct DropCounters {
    std::array<uint64_t, kWireErrorCount> by_error{};
    void count(WireError e) { ++by_error[static_cast<size_t>(e)]; }
    uint64_t operator[](WireError e) const { return by_error[static_cast<size_t>(e)]; }
    uint64_t total() const;
    DropCounters& operator+=(const DropCounters& o);
};

// ---- control channel (TCP): 8-byte header + payload --------------------------------------

enum class ControlType : uint8_t {
    kClientHello = 1,
    kServerChallenge = 2,
    kClientAuth = 3,
    kWelcome = 4,
    kFrameRequest = 5,
    kMediaAck = 6,
    kKeyFrameRequest = 7,
    kThroughputReport = 8,
    kBye = 9,
    kNack = 10,
    kRouteConfirm = 11,
    // The envelope of every control message after the handshake; not a ControlMessage itself.
    kSealed = 12,
    kKeepAlive = 13,
};

struct ControlHeader {
    ControlType type = ControlType::kBye;
    uint32_t payload_bytes = 0;
};

// What both ends must agree on for the media to make sense: the codec backend and the display
// profile (the layer sizes the server renders). Names are printable ASCII, NUL-padded; longer
// names are cut to kSettingNameBytes (the profile's numbers still tell two profiles apart).
// All zero: "unspecified", which only matches itself.
struct SessionSettings {
    std::array<uint8_t, kSettingNameBytes> codec{};
    std::array<uint8_t, kSettingNameBytes> profile{};
    uint16_t width_px = 0;  // per eye
    uint16_t height_px = 0;
    uint32_t refresh_mhz = 0;  // refresh rate in millihertz
    bool operator==(const SessionSettings&) const = default;
};
SessionSettings makeSessionSettings(std::string_view codec, std::string_view profile, int width_px,
                                    int height_px, double refresh_hz);
// "x264", or "small-320x360 320x360@90Hz" for the profile.
std::string codecNameOf(const SessionSettings& s);
std::string profileTextOf(const SessionSettings& s);

// Handshake (docs/PROTOCOL.md §Handshake): nonces both ways, HMAC proofs both ways, never the key.
struct ClientHello {
    std::array<uint8_t, kNonceBytes> client_nonce{};
    uint16_t media_port = 0;  // the client's UDP port on the address it connected from
    SessionSettings settings{};
};
struct ServerChallenge {
    std::array<uint8_t, kNonceBytes> server_nonce{};
    uint64_t session_id = 0;
    std::array<uint8_t, kMacBytes> server_proof{};
};
struct ClientAuth {
    std::array<uint8_t, kMacBytes> client_proof{};
};
struct Welcome {
    uint64_t session_id = 0;
    uint16_t media_port = 0;  // the server's UDP port media comes from
};

// What the server renders for one frame: the head pose, the gaze and the layer plan (§3.1).
struct LayerGeometry {
    PixelRect rect;
    float scale = 1.0f;
    int32_t width_px = 0;
    int32_t height_px = 0;
};
struct EyeGeometryWire {
    LayerGeometry fovea;
    LayerGeometry middle;
    LayerGeometry outer;
};
struct FrameRequest {
    uint32_t frame_id = 0;
    uint64_t client_send_ns = 0;  // the client's clock, echoed for its own latency bookkeeping
    Pose pose;
    Gaze gaze;
    float e1_deg = 0.0f;
    float e2_deg = 0.0f;
    float s1 = 1.0f;
    float s2 = 1.0f;
    std::array<EyeGeometryWire, 2> eyes;
};
FrameRequest makeFrameRequest(uint32_t frame_id, uint64_t client_send_ns, const Pose& pose,
                              const LayerPlan& plan);
// The plan's geometry as the server needs it (pixel counts recomputed from the rectangles).
LayerPlan layerPlanOf(const FrameRequest& request);

// One per stream of a frame, sent when the stream completed or was declared lost.
struct MediaAck {
    uint32_t frame_id = 0;
    uint8_t stream_id = 0;
    bool complete = false;
    uint16_t packets_received = 0;
    uint32_t bytes_received = 0;
    uint64_t first_rx_ns = 0;  // client clock: first and last packet of the stream's frame
    uint64_t last_rx_ns = 0;
    // The client's recent packet loss rate on the media streams, parts per million (≤ 10⁶),
    // from sequence gaps: the server sizes its FEC parity from it.
    uint32_t loss_ppm = 0;
};

enum class KeyFrameReason : uint8_t { kPacketLoss = 1, kDecoderError = 2, kStart = 3 };
struct KeyFrameRequest {
    uint8_t stream_mask = 0;     // bit s: stream s needs an intra frame
    uint32_t last_frame_id = 0;  // the frame whose loss triggered the request
    KeyFrameReason reason = KeyFrameReason::kPacketLoss;
};

// The server's ack-based estimate (§4.1, Eq. 2's Throughput), for LIWC on the headset.
struct ThroughputReport {
    uint64_t throughput_bps = 0;
    uint32_t samples = 0;
};

enum class ByeReason : uint8_t {
    kNormal = 0,
    kAuthFailed = 1,
    kProtocolError = 2,
    kServerFull = 3,
    kTimeout = 4,
    kVersionMismatch = 5,  // the ClientHello was of another protocol version
    kCodecMismatch = 6,    // the client's codec is not the server's
    kProfileMismatch = 7,  // nor its display profile
    kRouteUnverified = 8,  // the client never echoed the probe sent to its media port
    // One more headset would take the admitted ones below the server's frame-rate floor
    // (docs/RUNTIME.md §Admission); sent sealed, after authentication.
    kOverCapacity = 9,
};
inline constexpr uint8_t kMaxByeReason = 9;
std::string_view byeReasonName(ByeReason r);
// What the server did, for the client to tell its user after "the server ": "is full", ….
std::string_view byeReasonClientText(ByeReason r);
struct Bye {
    ByeReason reason = ByeReason::kNormal;
};

// Selective retransmission: the packets of one stream the client saw missing, as sequence
// numbers first_seq + i for each set bit i. By sequence number, so a frame whose packets were
// all lost can be asked for too.
struct Nack {
    uint8_t stream_id = 0;
    uint32_t first_seq = 0;
    uint64_t missing_mask = 0;  // ≠ 0
};

// The client's echo of the token the server sealed into the UDP probe (sealed, like every
// message after the handshake): proof that it receives at the media port it claimed.
struct RouteConfirm {
    RouteToken token{};
};

// A client with nothing else to say (its headset renders everything itself for a while, so it
// requests no layers and receives no media to acknowledge) sends this at least every
// kKeepAliveIntervalMs, so the server's idle timeout ends only clients that are really gone.
struct KeepAlive {
    uint64_t client_send_ns = 0;
};
inline constexpr int kKeepAliveIntervalMs = 2000;

// In type-id order (typeOf), kSealed left out.
using ControlMessage =
    std::variant<ClientHello, ServerChallenge, ClientAuth, Welcome, FrameRequest, MediaAck,
                 KeyFrameRequest, ThroughputReport, Bye, Nack, RouteConfirm, KeepAlive>;

// Header + payload, ready to write.
std::vector<uint8_t> encodeControl(const ControlMessage& message);
// The first kControlHeaderBytes of a message: magic, version, type, length ≤ the type's limit.
WireError decodeControlHeader(std::span<const uint8_t> bytes, ControlHeader& out);
// A payload of exactly header.payload_bytes.
WireError decodeControlPayload(ControlType type, std::span<const uint8_t> payload,
                               ControlMessage& out);
// A whole message (header + payload), nothing after it.
WireError decodeControl(std::span<const uint8_t> bytes, ControlMessage& out);

// ---- sealed control (docs/PROTOCOL.md §Sealed control) -------------------------------------

// Whether a message may travel sealed (Welcome onwards) — the handshake's three may not.
bool sealable(ControlType type);
// m encoded, then sealed with ChaCha20-Poly1305-IETF under `key` and nonce `counter`: a control
// message of type kSealed. Each direction has its own key and counts from 0; a counter is never
// used twice under one key. Precondition: sealable(type of m).
std::vector<uint8_t> sealControl(const ControlMessage& m, const ControlKey& key, uint64_t counter);
// A whole kSealed message (header + payload). Checks the header, then the tag (kBadMac: forged,
// altered, or sealed with another key), then that its counter is `next_counter` (kReplayed:
// replayed, reordered, or a message before it was deleted), and only then advances
// next_counter and decodes the inner message by the plain rules (a handshake type inside is
// kUnknownType). A plain message is kUnsealed.
WireError openControl(std::span<const uint8_t> bytes, const ControlKey& key, uint64_t& next_counter,
                      ControlMessage& out);

// The UDP probe of the return-routability check: magic 'Q' 'R', version, attempt, session_id
// (12 bytes in clear, associated data), then the token encrypted and a 16-byte tag.
std::vector<uint8_t> sealRouteProbe(uint64_t session_id, uint8_t attempt, const RouteToken& token,
                                    const ControlKey& key);
bool isRouteProbe(std::span<const uint8_t> datagram);  // magic only: not media
// Size, magic, version, tag (kBadMac), then the session (kWrongSession).
WireError openRouteProbe(std::span<const uint8_t> datagram, const ControlKey& key,
                         uint64_t session_id, RouteToken& token);

// ---- media streams (UDP datagrams): 32-byte header + payload ------------------------------

struct MediaHeader {
    bool key_frame = false;
    uint64_t session_id = 0;
    uint32_t seq = 0;  // per stream, +1 per packet across frames: gaps reveal loss
    uint32_t frame_id = 0;
    uint8_t stream_id = 0;
    uint16_t packet_index = 0;  // data: < packet_count; parity: < blocks · fec_parity
    uint16_t packet_count = 0;  // data packets of the frame
    uint16_t payload_bytes = 0;
    uint32_t frame_bytes = 0;  // the stream's encoded size for this frame
    // Forward error correction (fec.h): parity packets per block of this frame (0: none),
    // the same in all its packets; a parity packet has the flag and a full-size payload.
    uint8_t fec_parity = 0;
    bool parity = false;
};
// Parity packets a frame of packet_count data packets carries (every block gets fec_parity).
uint32_t parityPacketsFor(uint16_t packet_count, uint8_t fec_parity);
// The sequence number of the frame's first data packet (data, then parity, consecutively).
uint32_t frameFirstSeq(const MediaHeader& h);
struct MediaPacketView {
    MediaHeader header;
    std::span<const uint8_t> payload;  // into the datagram
};

// Checks every field against the limits and against each other: packet_count =
// ceil(frame_bytes / kMediaChunkBytes), packet_index < packet_count, and payload_bytes is
// kMediaChunkBytes except for the last packet, which carries the remainder.
WireError decodeMediaPacket(std::span<const uint8_t> datagram, MediaPacketView& out);
void encodeMediaPacket(const MediaHeader& header, std::span<const uint8_t> payload,
                       std::vector<uint8_t>& out);
uint32_t packetCountFor(uint32_t frame_bytes);

// ChaCha20-Poly1305-IETF over an encoded datagram, in place: the 32-byte header stays in clear
// as associated data, the payload is encrypted and the tag appended. The nonce is the header's
// (seq, stream_id), unique per session key while a stream's seq does not wrap (the server ends a
// session before it would); a retransmission resends the same sealed bytes.
void sealMediaPacket(std::vector<uint8_t>& datagram, const MediaKey& key);
// Checks size, magic and version in clear, then the tag (kBadMac), and decrypts in place: the
// first size − kMediaTagBytes bytes are then the plain datagram for decodeMediaPacket.
WireError openMediaPacket(std::span<uint8_t> sealed, const MediaKey& key);

// Sliding window over one stream's sequence numbers (sealed datagrams only: a forged seq never
// gets here): each seq is accepted once, and anything older than the window is refused.
class ReplayWindow {
public:
    static constexpr uint32_t kBits = 4096;
    bool accept(uint32_t seq);

private:
    bool m_started = false;
    uint32_t m_top = 0;
    std::array<uint64_t, kBits / 64> m_seen{};
    bool test(uint32_t seq) const { return (m_seen[(seq % kBits) / 64] >> (seq % 64)) & 1; }
    void set(uint32_t seq) { m_seen[(seq % kBits) / 64] |= uint64_t{1} << (seq % 64); }
    void clear(uint32_t seq) { m_seen[(seq % kBits) / 64] &= ~(uint64_t{1} << (seq % 64)); }
};
// Splits one stream's frame into datagrams, then fec_parity Reed-Solomon parity packets per
// block of kFecBlockData data packets (fec.h); seq advances by the packet count.
// Precondition: 0 < bytes.size() ≤ kMaxStreamFrameBytes, stream_id < kMaxStreams,
// fec_parity ≤ kFecMaxParity.
std::vector<std::vector<uint8_t>> packetizeStream(uint64_t session_id, uint32_t& seq,
                                                  uint32_t frame_id, uint8_t stream_id,
                                                  bool key_frame, std::span<const uint8_t> bytes,
                                                  uint8_t fec_parity = 0);

}  // namespace qvr::net
