// TOML config reading with range checks and unknown-key detection.
#include "qvr/core/config.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include <fmt/format.h>

namespace qvr {

Expected<toml::table> parseTomlText(std::string_view text, std::string_view source_name) {
    try {
        return toml::parse(text, source_name);
    } catch (const toml::parse_error& e) {
        const auto& where = e.source().begin;
        return makeError(
            fmt::format("{}:{}:{}: {}", source_name, where.line, where.column, e.description()));
    }
}

Expected<std::string> readTextFile(const std::string& path, size_t max_bytes) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return makeError(fmt::format("cannot open '{}'", path));
    std::string text;
    char buf[65536];
    while (in.read(buf, sizeof buf) || in.gcount() > 0) {
        text.append(buf, static_cast<size_t>(in.gcount()));
        if (text.size() > max_bytes)
            return makeError(fmt::format("'{}' is larger than {} bytes", path, max_bytes));
    }
    if (in.bad())
        return makeError(fmt::format("error reading '{}'", path));
    return text;
}

Expected<toml::table> loadTomlFile(const std::string& path) {
    auto text = readTextFile(path);
    if (!text)
        return makeError(text.error());
    return parseTomlText(*text, path);
}

ConfigReader::ConfigReader(const toml::table& table, std::string source_name)
    : m_table(table), m_source(std::move(source_name)) {}

void ConfigReader::fail(std::string message) {
    if (!m_errors.empty())
        m_errors += "\n";
    m_errors += fmt::format("{}: {}", m_source, message);
}

void ConfigReader::markUsed(std::string_view path) {
    // Mark the key and all its parent tables as known; a parent that holds a value instead of
    // a table ("display = 3" where [display] belongs) is an error, not a silent default.
    std::string p(path);
    bool leaf = true;
    while (true) {
        m_used.insert(p);
        if (!leaf) {
            const auto node = m_table.at_path(p);
            if (node && !node.is_table())
                fail(fmt::format("'{}' must be a table ([{}]), not a value", p, p));
        }
        leaf = false;
        const auto dot = p.rfind('.');
        if (dot == std::string::npos)
            break;
        p.resize(dot);
    }
}

bool ConfigReader::has(std::string_view path) const {
    return static_cast<bool>(m_table.at_path(path).node());
}

const toml::node* ConfigReader::present(std::string_view path, TypeTest is_type,
                                        const char* type_name) {
    markUsed(path);
    const toml::node* node = m_table.at_path(path).node();
    if (node == nullptr)
        return nullptr;
    if (!(node->*is_type)()) {
        fail(fmt::format("'{}' must be {}", path, type_name));
        return nullptr;
    }
    return node;
}

std::optional<double> ConfigReader::rangedNumber(const toml::node& node, const std::string& label,
                                                 double min_value, double max_value) {
    const std::optional<double> v = node.value<double>();
    if (!v || !node.is_number()) {
        fail(fmt::format("{} must be a number", label));
        return std::nullopt;
    }
    if (!std::isfinite(*v) || *v < min_value || *v > max_value) {
        fail(fmt::format("{} = {} is outside [{}, {}]", label, *v, min_value, max_value));
        return std::nullopt;
    }
    return v;
}

double ConfigReader::number(std::string_view path, double default_value, double min_value,
                            double max_value) {
    const toml::node* node = present(path, &toml::node::is_number, "a number");
    if (node == nullptr)
        return default_value;
    return rangedNumber(*node, fmt::format("'{}'", path), min_value, max_value)
        .value_or(default_value);
}

int ConfigReader::integer(std::string_view path, int default_value, int min_value, int max_value) {
    const toml::node* node = present(path, &toml::node::is_integer, "an integer");
    if (node == nullptr)
        return default_value;
    const int64_t v = *node->value<int64_t>();
    if (v < min_value || v > max_value) {
        fail(fmt::format("'{}' = {} is outside [{}, {}]", path, v, min_value, max_value));
        return default_value;
    }
    return static_cast<int>(v);
}

std::string ConfigReader::string(std::string_view path, std::string default_value) {
    const toml::node* node = present(path, &toml::node::is_string, "a string");
    return node != nullptr ? *node->value<std::string>() : default_value;
}

std::vector<double> ConfigReader::numbers(std::string_view path, double min_value, double max_value,
                                          size_t max_count) {
    const toml::node* node = present(path, &toml::node::is_array, "an array of numbers");
    if (node == nullptr)
        return {};
    const toml::array& arr = *node->as_array();
    if (arr.size() > max_count) {
        fail(fmt::format("'{}' has {} values, more than {}", path, arr.size(), max_count));
        return {};
    }
    std::vector<double> out;
    out.reserve(arr.size());
    for (size_t i = 0; i < arr.size(); ++i) {
        const auto v =
            rangedNumber(*arr.get(i), fmt::format("'{}'[{}]", path, i), min_value, max_value);
        if (!v)
            return {};
        out.push_back(*v);
    }
    return out;
}

Status ConfigReader::finish() {
    // Walk every key of the file; anything not asked for is unknown.
    std::function<void(const toml::table&, const std::string&)> walk =
        [&](const toml::table& t, const std::string& prefix) {
            for (const auto& [k, v] : t) {
                const std::string key =
                    prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
                if (!m_used.count(key)) {
                    fail(fmt::format("unknown key '{}'", key));
                    continue;
                }
                if (const auto* sub = v.as_table())
                    walk(*sub, key);
            }
        };
    walk(m_table, "");
    if (m_errors.empty())
        return Status::success();
    return makeError(m_errors);
}

}  // namespace qvr
