// A value or an error message a user can act on: the return type of everything that reads
// files, packets or configs (STYLE.md §5). C++20 has no std::expected, so this is the small
// subset qvr needs.
#pragma once

#include <string>
#include <utility>
#include <variant>

#include "qvr/core/check.h"

namespace qvr {

struct Error {
    std::string message;
};

inline Error makeError(std::string message) {
    return Error{std::move(message)};
}

template <typename T>
class Expected {
public:
    Expected(T value) : m_state(std::move(value)) {}      // NOLINT: implicit by design
    Expected(Error error) : m_state(std::move(error)) {}  // NOLINT: implicit by design

    bool ok() const { return std::holds_alternative<T>(m_state); }
    explicit operator bool() const { return ok(); }

    T& value() & {
        QVR_CHECK_MSG(ok(), "value() on an error");
        return std::get<T>(m_state);
    }
    const T& value() const& {
        QVR_CHECK_MSG(ok(), "value() on an error");
        return std::get<T>(m_state);
    }
    T&& value() && {
        QVR_CHECK_MSG(ok(), "value() on an error");
        return std::get<T>(std::move(m_state));
    }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

    const std::string& error() const {
        QVR_CHECK_MSG(!ok(), "error() on a value");
        return std::get<Error>(m_state).message;
    }

private:
    std::variant<T, Error> m_state;
};

// Status: success or an error, for operations with no value.
class Status {
public:
    Status() = default;
    Status(Error error) : m_error(std::move(error.message)), m_failed(true) {}  // NOLINT
    static Status success() { return {}; }
    bool ok() const { return !m_failed; }
    explicit operator bool() const { return ok(); }
    const std::string& error() const { return m_error; }

private:
    std::string m_error;
    bool m_failed = false;
};

}  // namespace qvr
