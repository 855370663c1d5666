// How a subcommand ends on an error: "qvr <command>: <message>" on stderr and its exit code
// (commands.h: 1 a runtime failure, 2 bad input).
#pragma once

#include <cstdio>
#include <string>

namespace qvr::cli {

inline int fail(const char* command, const std::string& message, int exit_code) {
    std::fprintf(stderr, "qvr %s: %s\n", command, message.c_str());
    return exit_code;
}

}  // namespace qvr::cli
