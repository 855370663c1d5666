// Whole-file writes (text_file.h).
#include "qvr/core/text_file.h"

#include <fstream>

#include <fmt/format.h>

namespace qvr {

Status writeTextFile(const std::string& path, std::string_view text) {
    std::ofstream out(path, std::ios::binary);
    if (!out)
        return makeError(fmt::format("cannot write '{}'", path));
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out)
        return makeError(fmt::format("error writing '{}'", path));
    return {};
}

Status writeJsonFile(const std::string& path, const nlohmann::json& document) {
    return writeTextFile(path, document.dump(2) + "\n");
}

}  // namespace qvr
