// Design names for the command line.
#include "qvr/runtime/runtime_design.h"

#include <sstream>

#include <fmt/format.h>

namespace qvr::runtime {

const char* designName(RuntimeDesign design) {
    switch (design) {
        case RuntimeDesign::kLocal:
            return "local";
        case RuntimeDesign::kRemote:
            return "remote";
        case RuntimeDesign::kFfr:
            return "ffr";
        case RuntimeDesign::kSw:
            return "sw";
        case RuntimeDesign::kQvr:
            return "qvr";
    }
    return "?";
}

const std::vector<RuntimeDesign>& allRuntimeDesigns() {
    static const std::vector<RuntimeDesign> designs = {RuntimeDesign::kLocal,
                                                       RuntimeDesign::kRemote, RuntimeDesign::kFfr,
                                                       RuntimeDesign::kSw, RuntimeDesign::kQvr};
    return designs;
}

Expected<RuntimeDesign> runtimeDesignByName(const std::string& name) {
    for (RuntimeDesign d : allRuntimeDesigns())
        if (name == designName(d))
            return d;
    return makeError(
        fmt::format("unknown design '{}': expected local, remote, ffr, sw or qvr", name));
}

Expected<std::vector<RuntimeDesign>> parseDesignList(const std::string& list) {
    std::vector<RuntimeDesign> out;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty())
            continue;
        auto d = runtimeDesignByName(item);
        if (!d)
            return makeError(d.error());
        out.push_back(*d);
    }
    if (out.empty())
        return makeError("no design named in '" + list + "'");
    return out;
}

bool usesServer(RuntimeDesign design) {
    return design != RuntimeDesign::kLocal;
}

}  // namespace qvr::runtime
