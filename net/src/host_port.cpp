#include "qvr/net/host_port.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>

namespace qvr {

bool parseHostPort(const std::string& text, std::string& host, uint16_t& port, std::string& error) {
    const size_t colon = text.rfind(':');
    if (colon == std::string::npos) {
        error = "must be HOST:PORT, got '" + text + "'";
        return false;
    }
    const std::string port_text = text.substr(colon + 1);
    unsigned long value = 0;
    if (port_text.empty() || port_text.size() > 5 ||
        port_text.find_first_not_of("0123456789") != std::string::npos ||
        (value = std::stoul(port_text)) == 0 || value > 65535) {
        error = "the port must be a number in 1..65535, got '" + port_text + "' in '" + text + "'";
        return false;
    }
    std::string h = text.substr(0, colon);
    unsigned char addr[16];
    if (h.size() >= 2 && h.front() == '[' && h.back() == ']') {
        h = h.substr(1, h.size() - 2);
        if (inet_pton(AF_INET6, h.c_str(), addr) != 1) {
            error = "'" + h + "' is not an IPv6 address";
            return false;
        }
    } else if (h.empty()) {
        error = "no host in '" + text + "' (HOST:PORT, e.g. 127.0.0.1:7400)";
        return false;
    } else if (h.find_first_not_of("0123456789.") == std::string::npos) {
        if (inet_pton(AF_INET, h.c_str(), addr) != 1) {
            error = "'" + h + "' is not an IPv4 address";
            return false;
        }
    } else if (h.find(':') != std::string::npos) {
        error = "an IPv6 address needs brackets: [" + h + "]:PORT";
        return false;
    } else {
        addrinfo hints{};
        hints.ai_socktype = SOCK_STREAM;
        addrinfo* found = nullptr;
        if (getaddrinfo(h.c_str(), nullptr, &hints, &found) != 0 || !found) {
            error = "cannot resolve host '" + h + "'";
            return false;
        }
        freeaddrinfo(found);
    }
    host = h;
    port = static_cast<uint16_t>(value);
    return true;
}

bool isIpAddress(const std::string& text) {
    unsigned char addr[16];
    return inet_pton(AF_INET, text.c_str(), addr) == 1 ||
           inet_pton(AF_INET6, text.c_str(), addr) == 1;
}

}  // namespace qvr
