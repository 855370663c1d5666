// A string as one POSIX shell word, for the command lines qvr hands to /bin/sh (gnuplot in the
// reports, `qvr calibrate` and `qvr run` in a validation sheet).
#pragma once

#include <string>

namespace qvr {

// Single-quoted; each ' inside is written '\'' (close, an escaped quote, reopen).
inline std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

}  // namespace qvr
