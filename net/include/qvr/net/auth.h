// The pre-shared-key handshake: both sides prove they hold the key by a MAC over fresh nonces,
// so the key never crosses the wire and a recorded handshake cannot be replayed. HMAC-SHA-256
// through libsodium; proofs compared in constant time. Layout: docs/PROTOCOL.md §Handshake.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/net/protocol.h"

namespace qvr::net {

inline constexpr size_t kKeyBytes = 32;

class PresharedKey {
public:
    PresharedKey() = default;
    // 64 hex digits: 32 random bytes, what `randomHex()` makes. The recommended form.
    static Expected<PresharedKey> fromHex(const std::string& hex);
    // Any non-empty text, hashed to 32 bytes with BLAKE2b. A short passphrase can be guessed
    // offline from a recorded handshake; use fromHex for anything but loopback tests.
    static Expected<PresharedKey> fromPassphrase(const std::string& passphrase);
    static PresharedKey random();
    std::string toHex() const;
    const std::array<uint8_t, kKeyBytes>& bytes() const { return m_key; }

private:
    std::array<uint8_t, kKeyBytes> m_key{};
};

using Nonce = std::array<uint8_t, kNonceBytes>;
using Mac = std::array<uint8_t, kMacBytes>;

Nonce randomNonce();
uint64_t randomSessionId();  // never 0

// server_proof = HMAC(K, "qvr1 server" ‖ client_nonce ‖ server_nonce ‖ session_id)
Mac serverProof(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                uint64_t session_id);
// client_proof = HMAC(K, "qvr1 client" ‖ client_nonce ‖ server_nonce ‖ session_id ‖ media_port)
Mac clientProof(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                uint64_t session_id, uint16_t media_port);
// Constant-time comparison.
bool macEqual(const Mac& a, const Mac& b);
// The session's media key: HMAC-SHA-256(K, "qvr2 media" ‖ Nc ‖ Ns ‖ sid), fresh per session,
// known only to the two ends that proved the key over these nonces.
MediaKey mediaKey(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                  uint64_t session_id);

// The session's control keys, one per direction, and the key of the return-routability probe:
// HMAC-SHA-256(K, "qvr4 control c2s" | "qvr4 control s2c" | "qvr4 route" ‖ Nc ‖ Ns ‖ sid).
struct SessionKeys {
    ControlKey client_to_server{};
    ControlKey server_to_client{};
    ControlKey route{};
};
SessionKeys sessionKeys(const PresharedKey& key, const Nonce& client_nonce,
                        const Nonce& server_nonce, uint64_t session_id);
// 16 random bytes for the return-routability check.
RouteToken randomRouteToken();
// Constant-time comparison.
bool tokenEqual(const RouteToken& a, const RouteToken& b);

}  // namespace qvr::net
