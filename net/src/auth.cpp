// PSK handshake proofs with libsodium's HMAC-SHA-256 and constant-time compare.
#include "qvr/net/auth.h"

#include <sodium.h>

#include <string_view>

#include "bytes.h"
#include "qvr/core/check.h"

namespace qvr::net {
namespace {

void ensureSodium() {
    // sodium_init is idempotent and thread-safe; < 0 means no usable randomness source.
    QVR_CHECK_MSG(sodium_init() >= 0, "libsodium failed to initialise");
}

Mac hmac(const PresharedKey& key, std::string_view label, const std::vector<uint8_t>& data) {
    ensureSodium();
    crypto_auth_hmacsha256_state state;
    crypto_auth_hmacsha256_init(&state, key.bytes().data(), key.bytes().size());
    crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(label.data()),
                                  label.size());
    crypto_auth_hmacsha256_update(&state, data.data(), data.size());
    Mac mac{};
    crypto_auth_hmacsha256_final(&state, mac.data());
    return mac;
}

std::vector<uint8_t> transcript(const Nonce& client_nonce, const Nonce& server_nonce,
                                uint64_t session_id) {
    std::vector<uint8_t> data;
    detail::ByteWriter w(data);
    w.bytes(client_nonce);
    w.bytes(server_nonce);
    w.u64(session_id);
    return data;
}

}  // namespace

Expected<PresharedKey> PresharedKey::fromHex(const std::string& hex) {
    ensureSodium();
    if (hex.size() != 2 * kKeyBytes) {
        return makeError("pre-shared key: expected " + std::to_string(2 * kKeyBytes) +
                         " hex digits, got " + std::to_string(hex.size()) + " characters");
    }
    PresharedKey key;
    size_t written = 0;
    if (sodium_hex2bin(key.m_key.data(), key.m_key.size(), hex.data(), hex.size(), nullptr,
                       &written, nullptr) != 0 ||
        written != kKeyBytes) {
        return makeError("pre-shared key: not a hex string");
    }
    return key;
}

Expected<PresharedKey> PresharedKey::fromPassphrase(const std::string& passphrase) {
    ensureSodium();
    if (passphrase.empty()) {
        return makeError("pre-shared key: empty passphrase");
    }
    PresharedKey key;
    crypto_generichash(key.m_key.data(), key.m_key.size(),
                       reinterpret_cast<const unsigned char*>(passphrase.data()), passphrase.size(),
                       nullptr, 0);
    return key;
}

PresharedKey PresharedKey::random() {
    ensureSodium();
    PresharedKey key;
    randombytes_buf(key.m_key.data(), key.m_key.size());
    return key;
}

std::string PresharedKey::toHex() const {
    std::string hex(2 * kKeyBytes + 1, '\0');
    sodium_bin2hex(hex.data(), hex.size(), m_key.data(), m_key.size());
    hex.pop_back();
    return hex;
}

Nonce randomNonce() {
    ensureSodium();
    Nonce n{};
    randombytes_buf(n.data(), n.size());
    return n;
}

uint64_t randomSessionId() {
    ensureSodium();
    uint64_t id = 0;
    while (id == 0) {
        randombytes_buf(&id, sizeof(id));
    }
    return id;
}

MediaKey mediaKey(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                  uint64_t session_id) {
    static_assert(kMediaKeyBytes == kMacBytes);
    return hmac(key, "qvr2 media", transcript(client_nonce, server_nonce, session_id));
}

SessionKeys sessionKeys(const PresharedKey& key, const Nonce& client_nonce,
                        const Nonce& server_nonce, uint64_t session_id) {
    static_assert(sizeof(ControlKey) == kMacBytes);
    const auto data = transcript(client_nonce, server_nonce, session_id);
    return {hmac(key, "qvr4 control c2s", data), hmac(key, "qvr4 control s2c", data),
            hmac(key, "qvr4 route", data)};
}

RouteToken randomRouteToken() {
    ensureSodium();
    RouteToken t{};
    randombytes_buf(t.data(), t.size());
    return t;
}

bool tokenEqual(const RouteToken& a, const RouteToken& b) {
    ensureSodium();
    static_assert(sizeof(RouteToken) == 16);
    return crypto_verify_16(a.data(), b.data()) == 0;
}

Mac serverProof(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                uint64_t session_id) {
    return hmac(key, "qvr1 server", transcript(client_nonce, server_nonce, session_id));
}

Mac clientProof(const PresharedKey& key, const Nonce& client_nonce, const Nonce& server_nonce,
                uint64_t session_id, uint16_t media_port) {
    std::vector<uint8_t> data = transcript(client_nonce, server_nonce, session_id);
    detail::ByteWriter(data).u16(media_port);
    return hmac(key, "qvr1 client", data);
}

bool macEqual(const Mac& a, const Mac& b) {
    ensureSodium();
    return crypto_verify_32(a.data(), b.data()) == 0;
}

}  // namespace qvr::net
