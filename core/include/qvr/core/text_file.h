// Writing a whole file from memory: the one place that opens it, writes it and says what failed.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"

namespace qvr {

// Writes `text` to `path`, replacing what was there: "cannot write 'PATH'" when the file cannot
// be opened, "error writing 'PATH'" when the write fails.
Status writeTextFile(const std::string& path, std::string_view text);

// A JSON document as every qvr output spells it: indented by two, a newline at the end.
Status writeJsonFile(const std::string& path, const nlohmann::json& document);

}  // namespace qvr
