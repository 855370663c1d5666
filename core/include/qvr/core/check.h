// Always-on contract checks (STYLE.md §5): a violated precondition is a bug, so abort with the
// file and line rather than limp on. Runtime failures use qvr::Expected instead.
#pragma once

#include <cstdio>
#include <cstdlib>

#define QVR_CHECK(cond)                                                                         \
    do {                                                                                        \
        if (!(cond)) {                                                                          \
            std::fprintf(stderr, "qvr: check failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
            std::abort();                                                                       \
        }                                                                                       \
    } while (0)

#define QVR_CHECK_MSG(cond, msg)                                                              \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            std::fprintf(stderr, "qvr: check failed: %s: %s (%s:%d)\n", #cond, msg, __FILE__, \
                         __LINE__);                                                           \
            std::abort();                                                                     \
        }                                                                                     \
    } while (0)
