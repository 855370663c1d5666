// Addresses as a user types them: "HOST:PORT" to connect to and a literal address to bind to.
#pragma once

#include <cstdint>
#include <string>

namespace qvr {

// "HOST:PORT" or "[IPV6]:PORT": PORT all digits in 1..65535; HOST an IPv4 or IPv6 address, or
// a name that resolves now. On failure `error` says what is wrong.
bool parseHostPort(const std::string& text, std::string& host, uint16_t& port, std::string& error);

// A bind address: an IPv4 or IPv6 literal (no names: a server binds to what it is told).
bool isIpAddress(const std::string& text);

}  // namespace qvr
