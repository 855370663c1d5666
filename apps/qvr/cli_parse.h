// Option parsers shared by several subcommands, so that `--gaze` means the same everywhere.
#pragma once

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>

#include "options.h"
#include "qvr/foveation/eye_geometry.h"

namespace qvr::cli {

// "X,Y": gaze angles in degrees right/up of the optical axis, each finite and within ±80.
inline bool parseGazeDeg(const std::string& text, Gaze& gaze) {
    double x = 0, y = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf%c", &x, &y, &tail) != 2)
        return false;
    if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(x) > 80 || std::fabs(y) > 80)
        return false;
    gaze = {x, y};
    return true;
}

// "HOST:PORT" or "[IPV6]:PORT": PORT all digits in 1..65535; HOST an IPv4 or IPv6 address, or
// a name that resolves now. On failure `error` says what is wrong.
inline bool parseHostPort(const std::string& text, std::string& host, uint16_t& port,
                          std::string& error) {
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

// A bind address: an IPv4 or IPv6 literal (no names: a server binds to what it is told).
inline bool isIpAddress(const std::string& text) {
    unsigned char addr[16];
    return inet_pton(AF_INET, text.c_str(), addr) == 1 ||
           inet_pton(AF_INET6, text.c_str(), addr) == 1;
}

// Checks, before any work, that `path` can be written (creates or truncates it), so that a run
// does not fail only at its end. An empty path is fine (nothing to write).
inline bool checkWritableFile(const std::string& path, std::string& error) {
    if (path.empty())
        return true;
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        error = "'" + path + "' is a directory";
        return false;
    }
    std::ofstream f(path, std::ios::app);
    if (!f) {
        error = "cannot write '" + path + "' (does its directory exist?)";
        return false;
    }
    return true;
}

// Creates the output folder up front; false (with `error`) when it cannot be.
inline bool makeOutputDir(const std::string& dir, std::string& error) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir)) {
        error = "cannot create the output folder '" + dir + "'" +
                (ec ? ": " + ec.message() : std::string());
        return false;
    }
    return true;
}

}  // namespace qvr::cli
