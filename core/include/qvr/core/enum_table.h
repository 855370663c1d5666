// An enum's text in one table: a row per value (its `value`, its `name`, and any other column
// the caller needs), so naming a value, parsing a name and reading another column all walk the
// same list. Tables are small; a linear walk is the lookup.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

namespace qvr {

// The plain row: a value and its name.
template <typename E>
struct EnumName {
    E value;
    const char* name;
};

// The row of `value` in `table`, or nullptr when the table has none.
template <typename Row, size_t N, typename E>
constexpr const Row* enumRow(const Row (&table)[N], E value) {
    for (const Row& row : table) {
        if (row.value == value)
            return &row;
    }
    return nullptr;
}

// The name of `value`, or `fallback` when the table has no row for it.
template <typename Row, size_t N, typename E>
constexpr const char* enumName(const Row (&table)[N], E value, const char* fallback = "?") {
    const Row* row = enumRow(table, value);
    return row != nullptr ? row->name : fallback;
}

// The value named `name`, or nullopt.
template <typename Row, size_t N>
constexpr auto enumFromName(const Row (&table)[N], std::string_view name)
    -> std::optional<decltype(table[0].value)> {
    for (const Row& row : table) {
        if (name == row.name)
            return row.value;
    }
    return std::nullopt;
}

}  // namespace qvr
