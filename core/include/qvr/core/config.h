// Config loading: TOML through toml++, with every value range-checked and every unknown key
// reported, so a typo in a profile is an error rather than a silently ignored setting.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "qvr/core/expected.h"

namespace qvr {

Expected<toml::table> parseTomlText(std::string_view text, std::string_view source_name);
Expected<toml::table> loadTomlFile(const std::string& path);
// Reads a whole file, refusing files larger than max_bytes.
Expected<std::string> readTextFile(const std::string& path, size_t max_bytes = size_t{1} << 20);

// Reads typed values out of one table. Errors accumulate; check ok() once at the end so a user
// sees every problem of a file in one message.
class ConfigReader {
public:
    ConfigReader(const toml::table& table, std::string source_name);

    // A number at a dotted path ("display.width_px"), within [min_value, max_value]. Returns the
    // default when absent; records an error when present but of the wrong type or out of range.
    double number(std::string_view path, double default_value, double min_value, double max_value);
    int integer(std::string_view path, int default_value, int min_value, int max_value);
    std::string string(std::string_view path, std::string default_value);
    // An array of numbers, each within [min_value, max_value], at most max_count of them. Empty
    // when absent; records an error (and returns empty) when present but not such an array.
    std::vector<double> numbers(std::string_view path, double min_value, double max_value,
                                size_t max_count);
    bool has(std::string_view path) const;

    // Fails if the file holds keys that nothing asked for.
    Status finish();

private:
    using TypeTest = bool (toml::node::*)() const noexcept;
    void fail(std::string message);
    void markUsed(std::string_view path);
    // The node at path when present and of the type `is_type` tests for; nullptr when absent, and
    // an error "'path' must be <type_name>" too when of another type. The key counts as used.
    const toml::node* present(std::string_view path, TypeTest is_type, const char* type_name);
    // The node's value when a finite number in [min, max]; else an error naming it by label.
    std::optional<double> rangedNumber(const toml::node& node, const std::string& label,
                                       double min_value, double max_value);

    const toml::table& m_table;
    std::string m_source;
    std::string m_errors;
    std::set<std::string> m_used;
};

}  // namespace qvr
