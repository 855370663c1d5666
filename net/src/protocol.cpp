// Encoders and decoders of the control messages and media packets (docs/PROTOCOL.md). Decoders
// read through ByteReader only, check every field's range, and allocate nothing.
#include "qvr/net/protocol.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>

#include <sodium.h>

#include "bytes.h"
#include "qvr/core/check.h"
#include "qvr/core/enum_table.h"
#include "qvr/net/fec.h"

namespace qvr::net {
namespace {

using detail::ByteReader;
using detail::ByteWriter;

constexpr uint8_t kControlMagic0 = 'Q';
constexpr uint8_t kControlMagic1 = 'C';
constexpr uint8_t kMediaMagic0 = 'Q';
constexpr uint8_t kMediaMagic1 = 'M';
constexpr uint8_t kFlagKeyFrame = 0x01;
constexpr uint8_t kFlagParity = 0x02;

constexpr size_t kLayerGeometryBytes = 4 * 4 + 4 + 4 + 4;  // rect, scale, width, height
constexpr size_t kFrameRequestBytes = 4 + 8 + 7 * 4 + 2 * 4 + 4 * 4 + 2 * 3 * kLayerGeometryBytes;

constexpr size_t kSettingsBytes = 2 * kSettingNameBytes + 2 + 2 + 4;

// The fixed payload size of each type; 0 for types this version does not define.
size_t payloadBytesOf(ControlType type) {
    switch (type) {
        case ControlType::kClientHello:
            return kNonceBytes + 2 + kSettingsBytes;
        case ControlType::kServerChallenge:
            return kNonceBytes + 8 + kMacBytes;
        case ControlType::kClientAuth:
            return kMacBytes;
        case ControlType::kWelcome:
            return 8 + 2;
        case ControlType::kFrameRequest:
            return kFrameRequestBytes;
        case ControlType::kMediaAck:
            return 4 + 1 + 1 + 2 + 4 + 8 + 8 + 4;
        case ControlType::kKeyFrameRequest:
            return 1 + 4 + 1;
        case ControlType::kThroughputReport:
            return 8 + 4;
        case ControlType::kBye:
            return 1;
        case ControlType::kNack:
            return 1 + 4 + 8;
        case ControlType::kRouteConfirm:
            return kRouteTokenBytes;
        case ControlType::kKeepAlive:
            return 8;
        case ControlType::kSealed:
            return 0;  // variable: checked by decodeControlHeader and openControl
    }
    return 0;
}

bool finiteIn(float v, float lo, float hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
}

void writeLayer(ByteWriter& w, const LayerGeometry& g) {
    w.i32(g.rect.x0);
    w.i32(g.rect.y0);
    w.i32(g.rect.x1);
    w.i32(g.rect.y1);
    w.f32(g.scale);
    w.i32(g.width_px);
    w.i32(g.height_px);
}

bool readLayer(ByteReader& r, LayerGeometry& g) {
    g.rect.x0 = r.i32();
    g.rect.y0 = r.i32();
    g.rect.x1 = r.i32();
    g.rect.y1 = r.i32();
    g.scale = r.f32();
    g.width_px = r.i32();
    g.height_px = r.i32();
    const auto coord = [](int32_t v) { return v >= 0 && v <= kMaxImageExtentPx; };
    return coord(g.rect.x0) && coord(g.rect.y0) && coord(g.rect.x1) && coord(g.rect.y1) &&
           g.rect.x0 <= g.rect.x1 && g.rect.y0 <= g.rect.y1 && finiteIn(g.scale, 1.0f, 64.0f) &&
           coord(g.width_px) && coord(g.height_px);
}

struct Encoder {
    ByteWriter& w;
    void operator()(const ClientHello& m) {
        w.bytes(m.client_nonce);
        w.u16(m.media_port);
        w.bytes(m.settings.codec);
        w.bytes(m.settings.profile);
        w.u16(m.settings.width_px);
        w.u16(m.settings.height_px);
        w.u32(m.settings.refresh_mhz);
    }
    void operator()(const ServerChallenge& m) {
        w.bytes(m.server_nonce);
        w.u64(m.session_id);
        w.bytes(m.server_proof);
    }
    void operator()(const ClientAuth& m) { w.bytes(m.client_proof); }
    void operator()(const Welcome& m) {
        w.u64(m.session_id);
        w.u16(m.media_port);
    }
    void operator()(const FrameRequest& m) {
        w.u32(m.frame_id);
        w.u64(m.client_send_ns);
        w.f32(m.pose.orientation.w);
        w.f32(m.pose.orientation.x);
        w.f32(m.pose.orientation.y);
        w.f32(m.pose.orientation.z);
        w.f32(m.pose.position_m.x);
        w.f32(m.pose.position_m.y);
        w.f32(m.pose.position_m.z);
        w.f32(static_cast<float>(m.gaze.x_deg));
        w.f32(static_cast<float>(m.gaze.y_deg));
        w.f32(m.e1_deg);
        w.f32(m.e2_deg);
        w.f32(m.s1);
        w.f32(m.s2);
        for (const EyeGeometryWire& eye : m.eyes) {
            writeLayer(w, eye.fovea);
            writeLayer(w, eye.middle);
            writeLayer(w, eye.outer);
        }
    }
    void operator()(const MediaAck& m) {
        w.u32(m.frame_id);
        w.u8(m.stream_id);
        w.u8(m.complete ? 1 : 0);
        w.u16(m.packets_received);
        w.u32(m.bytes_received);
        w.u64(m.first_rx_ns);
        w.u64(m.last_rx_ns);
        w.u32(m.loss_ppm);
    }
    void operator()(const KeyFrameRequest& m) {
        w.u8(m.stream_mask);
        w.u32(m.last_frame_id);
        w.u8(static_cast<uint8_t>(m.reason));
    }
    void operator()(const ThroughputReport& m) {
        w.u64(m.throughput_bps);
        w.u32(m.samples);
    }
    void operator()(const Bye& m) { w.u8(static_cast<uint8_t>(m.reason)); }
    void operator()(const Nack& m) {
        w.u8(m.stream_id);
        w.u32(m.first_seq);
        w.u64(m.missing_mask);
    }
    void operator()(const RouteConfirm& m) { w.bytes(m.token); }
    void operator()(const KeepAlive& m) { w.u64(m.client_send_ns); }
};

ControlType typeOf(const ControlMessage& m) {
    // The variant lists the types in id order, without the sealed envelope (12).
    const size_t id = m.index() + 1;
    return static_cast<ControlType>(id < static_cast<size_t>(ControlType::kSealed) ? id : id + 1);
}

WireError decodeFrameRequest(ByteReader& r, FrameRequest& m) {
    m.frame_id = r.u32();
    m.client_send_ns = r.u64();
    const float qw = r.f32(), qx = r.f32(), qy = r.f32(), qz = r.f32();
    const float px = r.f32(), py = r.f32(), pz = r.f32();
    const float gx = r.f32(), gy = r.f32();
    m.e1_deg = r.f32();
    m.e2_deg = r.f32();
    m.s1 = r.f32();
    m.s2 = r.f32();
    bool layers_ok = true;
    for (EyeGeometryWire& eye : m.eyes) {
        layers_ok = readLayer(r, eye.fovea) && layers_ok;
        layers_ok = readLayer(r, eye.middle) && layers_ok;
        layers_ok = readLayer(r, eye.outer) && layers_ok;
    }
    if (!r.ok()) {
        return WireError::kTruncated;
    }
    const bool quat_ok = finiteIn(qw, -1.01f, 1.01f) && finiteIn(qx, -1.01f, 1.01f) &&
                         finiteIn(qy, -1.01f, 1.01f) && finiteIn(qz, -1.01f, 1.01f) &&
                         std::fabs(qw * qw + qx * qx + qy * qy + qz * qz - 1.0f) < 0.01f;
    const bool pos_ok =
        finiteIn(px, -1e4f, 1e4f) && finiteIn(py, -1e4f, 1e4f) && finiteIn(pz, -1e4f, 1e4f);
    const bool plan_ok = finiteIn(gx, -90.0f, 90.0f) && finiteIn(gy, -90.0f, 90.0f) &&
                         finiteIn(m.e1_deg, 0.0f, 180.0f) && finiteIn(m.e2_deg, m.e1_deg, 180.0f) &&
                         finiteIn(m.s1, 1.0f, 64.0f) && finiteIn(m.s2, 1.0f, 64.0f);
    if (!quat_ok || !pos_ok || !plan_ok || !layers_ok) {
        return WireError::kBadField;
    }
    m.pose.orientation = glm::quat(qw, qx, qy, qz);
    m.pose.position_m = glm::vec3(px, py, pz);
    m.gaze = Gaze{gx, gy};
    return WireError::kNone;
}

// Printable ASCII, then only NUL padding.
bool validName(const std::array<uint8_t, kSettingNameBytes>& name) {
    bool ended = false;
    for (const uint8_t c : name) {
        if (c == 0) {
            ended = true;
        } else if (ended || c < 0x20 || c > 0x7e) {
            return false;
        }
    }
    return true;
}

std::array<uint8_t, kSettingNameBytes> nameBytes(std::string_view text) {
    std::array<uint8_t, kSettingNameBytes> out{};
    size_t n = 0;
    for (const char c : text) {
        if (n == out.size()) {
            break;
        }
        const auto u = static_cast<uint8_t>(c);
        out[n++] = u >= 0x20 && u <= 0x7e ? u : uint8_t{'?'};
    }
    return out;
}

std::string nameText(const std::array<uint8_t, kSettingNameBytes>& name) {
    std::string out;
    for (const uint8_t c : name) {
        if (c == 0) {
            break;
        }
        out.push_back(static_cast<char>(c));
    }
    return out;
}

}  // namespace

SessionSettings makeSessionSettings(std::string_view codec, std::string_view profile, int width_px,
                                    int height_px, double refresh_hz) {
    SessionSettings s;
    s.codec = nameBytes(codec);
    s.profile = nameBytes(profile);
    s.width_px = static_cast<uint16_t>(std::clamp(width_px, 0, 65535));
    s.height_px = static_cast<uint16_t>(std::clamp(height_px, 0, 65535));
    const double mhz = std::isfinite(refresh_hz) ? std::round(refresh_hz * 1000.0) : 0.0;
    s.refresh_mhz = static_cast<uint32_t>(std::clamp(mhz, 0.0, 4.0e9));
    return s;
}

std::string codecNameOf(const SessionSettings& s) {
    const std::string name = nameText(s.codec);
    return name.empty() ? "(unspecified)" : name;
}

std::string profileTextOf(const SessionSettings& s) {
    const std::string name = nameText(s.profile);
    char numbers[64];
    std::snprintf(numbers, sizeof numbers, " %ux%u@%.3gHz", unsigned{s.width_px},
                  unsigned{s.height_px}, s.refresh_mhz / 1000.0);
    return (name.empty() ? std::string("(unspecified)") : name) + numbers;
}

namespace {

// A bye reason's name (logs, summaries) and what the server did, as the client tells its user
// after "the server ".
struct ByeReasonRow {
    ByeReason value;
    const char* name;
    const char* client_text;
};

constexpr ByeReasonRow kByeReasons[] = {
    {ByeReason::kNormal, "normal", "closed the session"},
    {ByeReason::kAuthFailed, "auth failed", "refused the pre-shared key"},
    {ByeReason::kProtocolError, "protocol error", "reported a protocol error"},
    {ByeReason::kServerFull, "server full", "is full"},
    {ByeReason::kTimeout, "handshake timeout", "timed out the handshake"},
    {ByeReason::kVersionMismatch, "protocol version mismatch", "refused our protocol version"},
    {ByeReason::kCodecMismatch, "codec mismatch", "refused our codec (codec mismatch)"},
    {ByeReason::kProfileMismatch, "display profile mismatch",
     "refused our display profile (profile mismatch)"},
    {ByeReason::kRouteUnverified, "media port not verified",
     "could not verify that we receive media at our UDP port (no probe arrived or none was "
     "answered: a firewall or NAT in the way?)"},
    {ByeReason::kOverCapacity, "over capacity",
     "is at capacity: one more headset would take its headsets below its frame-rate floor (qvr "
     "server --min-fps); try another server"}};
static_assert(std::size(kByeReasons) == kMaxByeReason + 1u);

constexpr EnumName<WireError> kWireErrors[] = {{WireError::kNone, "none"},
                                               {WireError::kTruncated, "truncated"},
                                               {WireError::kOversized, "oversized"},
                                               {WireError::kBadMagic, "bad magic"},
                                               {WireError::kWrongVersion, "wrong version"},
                                               {WireError::kUnknownType, "unknown type"},
                                               {WireError::kBadField, "field out of range"},
                                               {WireError::kTrailingBytes, "trailing bytes"},
                                               {WireError::kBadMac, "bad MAC"},
                                               {WireError::kWrongSession, "wrong session"},
                                               {WireError::kReplayed, "replayed"},
                                               {WireError::kUnsealed, "unsealed"}};
static_assert(std::size(kWireErrors) == kWireErrorCount);

}  // namespace

std::string_view byeReasonName(ByeReason r) {
    return enumName(kByeReasons, r);
}

std::string_view byeReasonClientText(ByeReason r) {
    const ByeReasonRow* row = enumRow(kByeReasons, r);
    return row != nullptr ? row->client_text : "said bye";
}

std::string_view wireErrorName(WireError e) {
    return enumName(kWireErrors, e);
}

uint64_t DropCounters::total() const {
    uint64_t sum = 0;
    for (size_t i = 1; i < by_error.size(); ++i) {
        sum += by_error[i];
    }
    return sum;
}

DropCounters& DropCounters::operator+=(const DropCounters& o) {
    for (size_t i = 0; i < by_error.size(); ++i) {
        by_error[i] += o.by_error[i];
    }
    return *this;
}

FrameRequest makeFrameRequest(uint32_t frame_id, uint64_t client_send_ns, const Pose& pose,
                              const LayerPlan& plan) {
    FrameRequest r;
    r.frame_id = frame_id;
    r.client_send_ns = client_send_ns;
    r.pose = pose;
    r.gaze = plan.gaze;
    r.e1_deg = static_cast<float>(plan.e1_deg);
    r.e2_deg = static_cast<float>(plan.e2_deg);
    r.s1 = static_cast<float>(plan.s1);
    r.s2 = static_cast<float>(plan.s2);
    const auto wire = [](const LayerRect& l) {
        return LayerGeometry{l.rect, static_cast<float>(l.scale), l.width_px, l.height_px};
    };
    for (size_t e = 0; e < 2; ++e) {
        r.eyes[e] = {wire(plan.eyes[e].fovea), wire(plan.eyes[e].middle), wire(plan.eyes[e].outer)};
    }
    return r;
}

LayerPlan layerPlanOf(const FrameRequest& request) {
    LayerPlan plan;
    plan.gaze = request.gaze;
    plan.e1_deg = request.e1_deg;
    plan.e2_deg = request.e2_deg;
    plan.s1 = request.s1;
    plan.s2 = request.s2;
    const auto layer = [](const LayerGeometry& g) {
        return LayerRect{g.rect, g.scale, g.width_px, g.height_px};
    };
    for (size_t e = 0; e < 2; ++e) {
        plan.eyes[e] = {layer(request.eyes[e].fovea), layer(request.eyes[e].middle),
                        layer(request.eyes[e].outer)};
    }
    plan.fovea_pixels = plan.eyes[0].fovea.pixels();
    plan.middle_pixels = plan.eyes[0].middle.pixels();
    plan.outer_pixels = plan.eyes[0].outer.pixels();
    return plan;
}

std::vector<uint8_t> encodeControl(const ControlMessage& message) {
    std::vector<uint8_t> out;
    const ControlType type = typeOf(message);
    const size_t payload = payloadBytesOf(type);
    out.reserve(kControlHeaderBytes + payload);
    ByteWriter w(out);
    w.u8(kControlMagic0);
    w.u8(kControlMagic1);
    w.u8(kProtocolVersion);
    w.u8(static_cast<uint8_t>(type));
    w.u32(static_cast<uint32_t>(payload));
    std::visit(Encoder{w}, message);
    QVR_CHECK(out.size() == kControlHeaderBytes + payload);
    return out;
}

WireError decodeControlHeader(std::span<const uint8_t> bytes, ControlHeader& out) {
    if (bytes.size() < kControlHeaderBytes) {
        return WireError::kTruncated;
    }
    ByteReader r(bytes.first(kControlHeaderBytes));
    const uint8_t m0 = r.u8(), m1 = r.u8(), version = r.u8(), type = r.u8();
    const uint32_t length = r.u32();
    if (m0 != kControlMagic0 || m1 != kControlMagic1) {
        return WireError::kBadMagic;
    }
    if (version != kProtocolVersion) {
        return WireError::kWrongVersion;
    }
    if (static_cast<ControlType>(type) == ControlType::kSealed) {
        // Variable: the counter, at least a one-byte inner message, the tag.
        if (length > kMaxControlPayloadBytes) {
            return WireError::kOversized;
        }
        if (length < kSealedControlOverhead + 1) {
            return WireError::kTruncated;
        }
        out.type = ControlType::kSealed;
        out.payload_bytes = length;
        return WireError::kNone;
    }
    const size_t expected = payloadBytesOf(static_cast<ControlType>(type));
    if (expected == 0) {
        return WireError::kUnknownType;
    }
    if (length > kMaxControlPayloadBytes) {
        return WireError::kOversized;
    }
    if (length < expected) {
        return WireError::kTruncated;
    }
    if (length > expected) {
        return WireError::kTrailingBytes;
    }
    out.type = static_cast<ControlType>(type);
    out.payload_bytes = length;
    return WireError::kNone;
}

namespace {

// A one-byte enum from r into out when it is one of first…last; else out is left as it was.
template <typename Enum>
bool readEnum(ByteReader& r, Enum first, Enum last, Enum& out) {
    const uint8_t value = r.u8();
    if (value < static_cast<uint8_t>(first) || value > static_cast<uint8_t>(last))
        return false;
    out = static_cast<Enum>(value);
    return true;
}

// Each control message's fields from r, range-checked; decodeFrameRequest is FrameRequest's.
WireError decodeBody(ByteReader& r, ClientHello& m) {
    r.bytes(m.client_nonce);
    m.media_port = r.u16();
    r.bytes(m.settings.codec);
    r.bytes(m.settings.profile);
    m.settings.width_px = r.u16();
    m.settings.height_px = r.u16();
    m.settings.refresh_mhz = r.u32();
    const bool ok =
        m.media_port != 0 && validName(m.settings.codec) && validName(m.settings.profile);
    return ok ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, ServerChallenge& m) {
    r.bytes(m.server_nonce);
    m.session_id = r.u64();
    r.bytes(m.server_proof);
    return m.session_id != 0 ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, ClientAuth& m) {
    r.bytes(m.client_proof);
    return WireError::kNone;
}

WireError decodeBody(ByteReader& r, Welcome& m) {
    m.session_id = r.u64();
    m.media_port = r.u16();
    return m.session_id != 0 && m.media_port != 0 ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, FrameRequest& m) {
    return decodeFrameRequest(r, m);
}

WireError decodeBody(ByteReader& r, MediaAck& m) {
    m.frame_id = r.u32();
    m.stream_id = r.u8();
    const uint8_t complete = r.u8();
    m.packets_received = r.u16();
    m.bytes_received = r.u32();
    m.first_rx_ns = r.u64();
    m.last_rx_ns = r.u64();
    m.loss_ppm = r.u32();
    m.complete = complete == 1;
    if (m.stream_id >= kMaxStreams || complete > 1 || m.packets_received > kMaxPacketsPerFrame ||
        m.bytes_received > kMaxStreamFrameBytes || m.last_rx_ns < m.first_rx_ns ||
        m.loss_ppm > 1'000'000) {
        return WireError::kBadField;
    }
    return WireError::kNone;
}

WireError decodeBody(ByteReader& r, KeyFrameRequest& m) {
    m.stream_mask = r.u8();
    m.last_frame_id = r.u32();
    const bool reason_ok =
        readEnum(r, KeyFrameReason::kPacketLoss, KeyFrameReason::kStart, m.reason);
    const bool ok = reason_ok && m.stream_mask != 0 && m.stream_mask < (1u << kMaxStreams);
    return ok ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, ThroughputReport& m) {
    m.throughput_bps = r.u64();
    m.samples = r.u32();
    return m.throughput_bps <= 1'000'000'000'000ull ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, Bye& m) {
    const bool ok =
        readEnum(r, ByeReason::kNormal, static_cast<ByeReason>(kMaxByeReason), m.reason);
    return ok ? WireError::kNone : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, Nack& m) {
    m.stream_id = r.u8();
    m.first_seq = r.u32();
    m.missing_mask = r.u64();
    return m.stream_id < kMaxStreams && m.missing_mask != 0 ? WireError::kNone
                                                            : WireError::kBadField;
}

WireError decodeBody(ByteReader& r, RouteConfirm& m) {
    r.bytes(m.token);
    return WireError::kNone;
}

WireError decodeBody(ByteReader& r, KeepAlive& m) {
    m.client_send_ns = r.u64();
    return WireError::kNone;
}

// A T into out when its fields are in range; out is left alone otherwise.
template <typename T>
WireError decodeInto(ByteReader& r, ControlMessage& out) {
    T m;
    const WireError e = decodeBody(r, m);
    if (e == WireError::kNone) {
        out = m;
    }
    return e;
}

}  // namespace

WireError decodeControlPayload(ControlType type, std::span<const uint8_t> payload,
                               ControlMessage& out) {
    const size_t expected = payloadBytesOf(type);
    if (expected == 0) {
        return WireError::kUnknownType;
    }
    if (payload.size() < expected) {
        return WireError::kTruncated;
    }
    if (payload.size() > expected) {
        return WireError::kTrailingBytes;
    }
    ByteReader r(payload);
    WireError e = WireError::kUnknownType;  // kSealed: unreachable, payloadBytesOf is 0
    switch (type) {
        case ControlType::kClientHello:
            e = decodeInto<ClientHello>(r, out);
            break;
        case ControlType::kServerChallenge:
            e = decodeInto<ServerChallenge>(r, out);
            break;
        case ControlType::kClientAuth:
            e = decodeInto<ClientAuth>(r, out);
            break;
        case ControlType::kWelcome:
            e = decodeInto<Welcome>(r, out);
            break;
        case ControlType::kFrameRequest:
            e = decodeInto<FrameRequest>(r, out);
            break;
        case ControlType::kMediaAck:
            e = decodeInto<MediaAck>(r, out);
            break;
        case ControlType::kKeyFrameRequest:
            e = decodeInto<KeyFrameRequest>(r, out);
            break;
        case ControlType::kThroughputReport:
            e = decodeInto<ThroughputReport>(r, out);
            break;
        case ControlType::kBye:
            e = decodeInto<Bye>(r, out);
            break;
        case ControlType::kNack:
            e = decodeInto<Nack>(r, out);
            break;
        case ControlType::kRouteConfirm:
            e = decodeInto<RouteConfirm>(r, out);
            break;
        case ControlType::kKeepAlive:
            e = decodeInto<KeepAlive>(r, out);
            break;
        case ControlType::kSealed:
            break;
    }
    if (e != WireError::kNone) {
        return e;
    }
    return r.ok() ? WireError::kNone : WireError::kTruncated;
}

WireError decodeControl(std::span<const uint8_t> bytes, ControlMessage& out) {
    ControlHeader header;
    const WireError e = decodeControlHeader(bytes, header);
    if (e != WireError::kNone) {
        return e;
    }
    const size_t total = kControlHeaderBytes + header.payload_bytes;
    if (bytes.size() < total) {
        return WireError::kTruncated;
    }
    if (bytes.size() > total) {
        return WireError::kTrailingBytes;
    }
    return decodeControlPayload(header.type, bytes.subspan(kControlHeaderBytes), out);
}

uint32_t packetCountFor(uint32_t frame_bytes) {
    return static_cast<uint32_t>((static_cast<uint64_t>(frame_bytes) + kMediaChunkBytes - 1) /
                                 kMediaChunkBytes);
}

WireError decodeMediaPacket(std::span<const uint8_t> datagram, MediaPacketView& out) {
    if (datagram.size() < kMediaHeaderBytes) {
        return WireError::kTruncated;
    }
    if (datagram.size() > kMaxDatagramBytes) {
        return WireError::kOversized;
    }
    ByteReader r(datagram.first(kMediaHeaderBytes));
    const uint8_t m0 = r.u8(), m1 = r.u8(), version = r.u8(), flags = r.u8();
    MediaHeader h;
    h.session_id = r.u64();
    h.seq = r.u32();
    h.frame_id = r.u32();
    h.stream_id = r.u8();
    h.fec_parity = r.u8();
    h.packet_index = r.u16();
    h.packet_count = r.u16();
    h.payload_bytes = r.u16();
    h.frame_bytes = r.u32();
    if (m0 != kMediaMagic0 || m1 != kMediaMagic1) {
        return WireError::kBadMagic;
    }
    if (version != kProtocolVersion) {
        return WireError::kWrongVersion;
    }
    if (h.payload_bytes > kMediaChunkBytes || h.packet_count > kMaxPacketsPerFrame ||
        h.frame_bytes > kMaxStreamFrameBytes) {
        return WireError::kOversized;
    }
    const size_t available = datagram.size() - kMediaHeaderBytes;
    if (available < h.payload_bytes) {
        return WireError::kTruncated;
    }
    if (available > h.payload_bytes) {
        return WireError::kTrailingBytes;
    }
    h.key_frame = (flags & kFlagKeyFrame) != 0;
    h.parity = (flags & kFlagParity) != 0;
    const bool frame_ok = (flags & ~(kFlagKeyFrame | kFlagParity)) == 0 &&
                          h.fec_parity <= kFecMaxParity && h.stream_id < kMaxStreams &&
                          h.session_id != 0 && h.frame_bytes > 0 &&
                          h.packet_count == packetCountFor(h.frame_bytes);
    // A parity packet carries a full shard; a data packet its part of the frame.
    const bool consistent =
        frame_ok &&
        (h.parity ? h.fec_parity > 0 &&
                        h.packet_index < parityPacketsFor(h.packet_count, h.fec_parity) &&
                        h.payload_bytes == kMediaChunkBytes
                  : h.packet_index < h.packet_count &&
                        h.payload_bytes ==
                            (h.packet_index + 1u < h.packet_count
                                 ? kMediaChunkBytes
                                 : h.frame_bytes - (h.packet_count - 1u) * kMediaChunkBytes));
    if (!consistent) {
        return WireError::kBadField;
    }
    out.header = h;
    out.payload = datagram.subspan(kMediaHeaderBytes, h.payload_bytes);
    return WireError::kNone;
}

void encodeMediaPacket(const MediaHeader& h, std::span<const uint8_t> payload,
                       std::vector<uint8_t>& out) {
    QVR_CHECK(payload.size() <= kMediaChunkBytes && payload.size() == h.payload_bytes);
    out.clear();
    out.reserve(kMediaHeaderBytes + payload.size());
    ByteWriter w(out);
    w.u8(kMediaMagic0);
    w.u8(kMediaMagic1);
    w.u8(kProtocolVersion);
    w.u8(static_cast<uint8_t>((h.key_frame ? kFlagKeyFrame : 0) | (h.parity ? kFlagParity : 0)));
    w.u64(h.session_id);
    w.u32(h.seq);
    w.u32(h.frame_id);
    w.u8(h.stream_id);
    w.u8(h.fec_parity);
    w.u16(h.packet_index);
    w.u16(h.packet_count);
    w.u16(h.payload_bytes);
    w.u32(h.frame_bytes);
    w.bytes(payload);
}

std::vector<std::vector<uint8_t>> packetizeStream(uint64_t session_id, uint32_t& seq,
                                                  uint32_t frame_id, uint8_t stream_id,
                                                  bool key_frame, std::span<const uint8_t> bytes,
                                                  uint8_t fec_parity) {
    QVR_CHECK(!bytes.empty() && bytes.size() <= kMaxStreamFrameBytes);
    QVR_CHECK(stream_id < kMaxStreams && fec_parity <= kFecMaxParity);
    const uint32_t frame_bytes = static_cast<uint32_t>(bytes.size());
    const uint32_t count = packetCountFor(frame_bytes);
    const uint32_t parity_count = parityPacketsFor(static_cast<uint16_t>(count), fec_parity);
    std::vector<std::vector<uint8_t>> packets(count + parity_count);
    // Data and parity packets differ only in their index, payload and parity flag.
    auto header = [&](uint32_t index, size_t payload_bytes, bool parity) {
        MediaHeader h;
        h.key_frame = key_frame;
        h.session_id = session_id;
        h.seq = seq++;
        h.frame_id = frame_id;
        h.stream_id = stream_id;
        h.packet_index = static_cast<uint16_t>(index);
        h.packet_count = static_cast<uint16_t>(count);
        h.payload_bytes = static_cast<uint16_t>(payload_bytes);
        h.frame_bytes = frame_bytes;
        h.fec_parity = fec_parity;
        h.parity = parity;
        return h;
    };
    for (uint32_t i = 0; i < count; ++i) {
        const size_t offset = static_cast<size_t>(i) * kMediaChunkBytes;
        const size_t n = std::min(kMediaChunkBytes, bytes.size() - offset);
        encodeMediaPacket(header(i, n, false), bytes.subspan(offset, n), packets[i]);
    }
    if (parity_count == 0) {
        return packets;
    }
    // The code works on whole shards: the frame's last data packet is zero-padded.
    std::vector<uint8_t> padded(static_cast<size_t>(count) * kMediaChunkBytes, 0);
    std::copy(bytes.begin(), bytes.end(), padded.begin());
    std::vector<uint8_t> parity(static_cast<size_t>(parity_count) * kMediaChunkBytes);
    const int k = static_cast<int>(count);
    for (int b = 0; b < fecBlockCount(k); ++b) {
        std::vector<const uint8_t*> data;
        for (int i = 0; i < fecBlockSize(k, b); ++i) {
            data.push_back(padded.data() +
                           static_cast<size_t>(fecBlockFirst(b) + i) * kMediaChunkBytes);
        }
        std::vector<uint8_t*> out;
        for (int j = 0; j < fec_parity; ++j) {
            out.push_back(parity.data() +
                          static_cast<size_t>(b * fec_parity + j) * kMediaChunkBytes);
        }
        fecEncode(static_cast<int>(kMediaChunkBytes), data, out);
    }
    for (uint32_t j = 0; j < parity_count; ++j) {
        encodeMediaPacket(header(j, kMediaChunkBytes, true),
                          std::span<const uint8_t>(parity).subspan(
                              static_cast<size_t>(j) * kMediaChunkBytes, kMediaChunkBytes),
                          packets[count + j]);
    }
    return packets;
}

uint32_t parityPacketsFor(uint16_t packet_count, uint8_t fec_parity) {
    return static_cast<uint32_t>(fecBlockCount(packet_count)) * fec_parity;
}

uint32_t frameFirstSeq(const MediaHeader& h) {
    return h.seq - h.packet_index - (h.parity ? h.packet_count : 0u);
}

namespace {

std::array<uint8_t, crypto_aead_chacha20poly1305_IETF_NPUBBYTES> mediaNonce(
    std::span<const uint8_t> header) {
    std::array<uint8_t, crypto_aead_chacha20poly1305_IETF_NPUBBYTES> nonce{};
    std::memcpy(nonce.data(), header.data() + 12, 4);  // seq, little-endian as on the wire
    nonce[4] = header[20];                             // stream_id
    return nonce;
}

}  // namespace

void sealMediaPacket(std::vector<uint8_t>& datagram, const MediaKey& key) {
    QVR_CHECK(datagram.size() >= kMediaHeaderBytes);
    const auto nonce = mediaNonce(datagram);
    const size_t payload = datagram.size() - kMediaHeaderBytes;
    datagram.resize(datagram.size() + kMediaTagBytes);
    unsigned long long tag_len = 0;
    crypto_aead_chacha20poly1305_ietf_encrypt_detached(
        datagram.data() + kMediaHeaderBytes, datagram.data() + kMediaHeaderBytes + payload,
        &tag_len, datagram.data() + kMediaHeaderBytes, payload, datagram.data(), kMediaHeaderBytes,
        nullptr, nonce.data(), key.data());
}

WireError openMediaPacket(std::span<uint8_t> sealed, const MediaKey& key) {
    if (sealed.size() > kMaxSealedDatagramBytes) {
        return WireError::kOversized;
    }
    if (sealed.size() < kMediaHeaderBytes + kMediaTagBytes) {
        return WireError::kTruncated;
    }
    if (sealed[0] != kMediaMagic0 || sealed[1] != kMediaMagic1) {
        return WireError::kBadMagic;
    }
    if (sealed[2] != kProtocolVersion) {
        return WireError::kWrongVersion;
    }
    const auto nonce = mediaNonce(sealed);
    const size_t payload = sealed.size() - kMediaHeaderBytes - kMediaTagBytes;
    if (crypto_aead_chacha20poly1305_ietf_decrypt_detached(
            sealed.data() + kMediaHeaderBytes, nullptr, sealed.data() + kMediaHeaderBytes, payload,
            sealed.data() + kMediaHeaderBytes + payload, sealed.data(), kMediaHeaderBytes,
            nonce.data(), key.data()) != 0) {
        return WireError::kBadMac;
    }
    return WireError::kNone;
}

namespace {

constexpr uint8_t kRouteMagic0 = 'Q';
constexpr uint8_t kRouteMagic1 = 'R';
using AeadNonce = std::array<uint8_t, crypto_aead_chacha20poly1305_IETF_NPUBBYTES>;

AeadNonce counterNonce(uint64_t counter) {
    AeadNonce nonce{};
    for (size_t i = 0; i < 8; ++i) {
        nonce[i] = static_cast<uint8_t>(counter >> (8 * i));
    }
    return nonce;
}

}  // namespace

bool sealable(ControlType type) {
    switch (type) {
        case ControlType::kWelcome:
        case ControlType::kFrameRequest:
        case ControlType::kMediaAck:
        case ControlType::kKeyFrameRequest:
        case ControlType::kThroughputReport:
        case ControlType::kBye:
        case ControlType::kNack:
        case ControlType::kRouteConfirm:
        case ControlType::kKeepAlive:
            return true;
        case ControlType::kClientHello:
        case ControlType::kServerChallenge:
        case ControlType::kClientAuth:
        case ControlType::kSealed:
            return false;
    }
    return false;
}

std::vector<uint8_t> sealControl(const ControlMessage& m, const ControlKey& key, uint64_t counter) {
    const ControlType type = typeOf(m);
    QVR_CHECK(sealable(type));
    const std::vector<uint8_t> plain = encodeControl(m);
    const size_t inner = 1 + plain.size() - kControlHeaderBytes;
    const size_t payload = 8 + inner + kControlTagBytes;
    std::vector<uint8_t> out;
    out.reserve(kControlHeaderBytes + payload);
    ByteWriter w(out);
    w.u8(kControlMagic0);
    w.u8(kControlMagic1);
    w.u8(kProtocolVersion);
    w.u8(static_cast<uint8_t>(ControlType::kSealed));
    w.u32(static_cast<uint32_t>(payload));
    w.u64(counter);
    w.u8(static_cast<uint8_t>(type));
    w.bytes(std::span<const uint8_t>(plain).subspan(kControlHeaderBytes));
    out.resize(kControlHeaderBytes + payload);
    constexpr size_t kAd = kControlHeaderBytes + 8;  // header and counter in clear
    const AeadNonce nonce = counterNonce(counter);
    unsigned long long tag_len = 0;
    crypto_aead_chacha20poly1305_ietf_encrypt_detached(
        out.data() + kAd, out.data() + kAd + inner, &tag_len, out.data() + kAd, inner, out.data(),
        kAd, nullptr, nonce.data(), key.data());
    return out;
}

WireError openControl(std::span<const uint8_t> bytes, const ControlKey& key, uint64_t& next_counter,
                      ControlMessage& out) {
    ControlHeader header;
    const WireError e = decodeControlHeader(bytes, header);
    if (e != WireError::kNone) {
        return e;
    }
    if (header.type != ControlType::kSealed) {
        return WireError::kUnsealed;
    }
    const size_t total = kControlHeaderBytes + header.payload_bytes;
    if (bytes.size() < total) {
        return WireError::kTruncated;
    }
    if (bytes.size() > total) {
        return WireError::kTrailingBytes;
    }
    constexpr size_t kAd = kControlHeaderBytes + 8;
    uint64_t counter = 0;
    for (size_t i = 0; i < 8; ++i) {
        counter |= static_cast<uint64_t>(bytes[kControlHeaderBytes + i]) << (8 * i);
    }
    // decodeControlHeader bounded the payload: inner < kMaxControlPayloadBytes.
    const size_t inner = header.payload_bytes - 8 - kControlTagBytes;
    std::array<uint8_t, kMaxControlPayloadBytes> plain{};
    const AeadNonce nonce = counterNonce(counter);
    if (crypto_aead_chacha20poly1305_ietf_decrypt_detached(
            plain.data(), nullptr, bytes.data() + kAd, inner, bytes.data() + kAd + inner,
            bytes.data(), kAd, nonce.data(), key.data()) != 0) {
        return WireError::kBadMac;
    }
    if (counter != next_counter) {
        return WireError::kReplayed;
    }
    ++next_counter;
    const auto type = static_cast<ControlType>(plain[0]);
    if (!sealable(type)) {
        return WireError::kUnknownType;
    }
    return decodeControlPayload(type, std::span<const uint8_t>(plain.data() + 1, inner - 1), out);
}

std::vector<uint8_t> sealRouteProbe(uint64_t session_id, uint8_t attempt, const RouteToken& token,
                                    const ControlKey& key) {
    std::vector<uint8_t> out;
    out.reserve(kRouteProbeBytes);
    ByteWriter w(out);
    w.u8(kRouteMagic0);
    w.u8(kRouteMagic1);
    w.u8(kProtocolVersion);
    w.u8(attempt);
    w.u64(session_id);
    w.bytes(token);
    out.resize(kRouteProbeBytes);
    const AeadNonce nonce = counterNonce(attempt);
    unsigned long long tag_len = 0;
    crypto_aead_chacha20poly1305_ietf_encrypt_detached(
        out.data() + kRouteProbeHeaderBytes, out.data() + kRouteProbeHeaderBytes + kRouteTokenBytes,
        &tag_len, out.data() + kRouteProbeHeaderBytes, kRouteTokenBytes, out.data(),
        kRouteProbeHeaderBytes, nullptr, nonce.data(), key.data());
    return out;
}

bool isRouteProbe(std::span<const uint8_t> datagram) {
    return datagram.size() >= 2 && datagram[0] == kRouteMagic0 && datagram[1] == kRouteMagic1;
}

WireError openRouteProbe(std::span<const uint8_t> datagram, const ControlKey& key,
                         uint64_t session_id, RouteToken& token) {
    if (datagram.size() < kRouteProbeBytes) {
        return WireError::kTruncated;
    }
    if (datagram.size() > kRouteProbeBytes) {
        return WireError::kTrailingBytes;
    }
    if (!isRouteProbe(datagram)) {
        return WireError::kBadMagic;
    }
    if (datagram[2] != kProtocolVersion) {
        return WireError::kWrongVersion;
    }
    const AeadNonce nonce = counterNonce(datagram[3]);
    RouteToken plain{};
    if (crypto_aead_chacha20poly1305_ietf_decrypt_detached(
            plain.data(), nullptr, datagram.data() + kRouteProbeHeaderBytes, kRouteTokenBytes,
            datagram.data() + kRouteProbeHeaderBytes + kRouteTokenBytes, datagram.data(),
            kRouteProbeHeaderBytes, nonce.data(), key.data()) != 0) {
        return WireError::kBadMac;
    }
    uint64_t sid = 0;
    for (size_t i = 0; i < 8; ++i) {
        sid |= static_cast<uint64_t>(datagram[4 + i]) << (8 * i);
    }
    if (sid != session_id) {
        return WireError::kWrongSession;
    }
    token = plain;
    return WireError::kNone;
}

bool ReplayWindow::accept(uint32_t seq) {
    if (!m_started) {
        m_started = true;
        m_top = seq;
        set(seq);
        return true;
    }
    const int64_t ahead = static_cast<int32_t>(seq - m_top);
    if (ahead > 0) {
        if (ahead >= kBits) {
            m_seen.fill(0);
        } else {
            for (uint32_t k = 1; k <= static_cast<uint32_t>(ahead); ++k) {
                clear(m_top + k);
            }
        }
        m_top = seq;
        set(seq);
        return true;
    }
    if (-ahead >= kBits || test(seq)) {
        return false;
    }
    set(seq);
    return true;
}

}  // namespace qvr::net
