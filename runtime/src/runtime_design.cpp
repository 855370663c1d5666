// Design names for the command line.
#include "qvr/runtime/runtime_design.h"

#include <cmath>
#include <sstream>
#include <string_view>

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
        case RuntimeDesign::kFixed:
            return "fixed";
    }
    return "?";
}

std::string designLabel(RuntimeDesign design, double fixed_e1_deg) {
    if (design == RuntimeDesign::kFixed)
        return fmt::format("fixed:{:g}", fixed_e1_deg);
    return designName(design);
}

std::string DesignSpec::label() const {
    return designLabel(design, fixed_e1_deg);
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
        fmt::format("unknown design '{}': expected local, remote, ffr, sw, qvr or fixed:E", name));
}

Expected<DesignSpec> designSpecByName(const std::string& name) {
    constexpr std::string_view kFixedPrefix = "fixed:";
    if (name.rfind(kFixedPrefix, 0) == 0) {
        const std::string num = name.substr(kFixedPrefix.size());
        double e1 = 0.0;
        size_t used = 0;
        try {
            e1 = std::stod(num, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (num.empty() || used != num.size() || !std::isfinite(e1) || e1 < kFixedE1MinDeg ||
            e1 > kFixedE1MaxDeg)
            return makeError(fmt::format("design '{}': fixed:E needs E in degrees, {:g}…{:g}", name,
                                         kFixedE1MinDeg, kFixedE1MaxDeg));
        return DesignSpec{RuntimeDesign::kFixed, e1};
    }
    auto d = runtimeDesignByName(name);
    if (!d)
        return makeError(d.error());
    if (*d == RuntimeDesign::kFixed)
        return makeError("design 'fixed' needs its e1: fixed:E, e.g. fixed:10");
    return DesignSpec{*d, kFfrE1Deg};
}

Expected<std::vector<DesignSpec>> parseDesignList(const std::string& list) {
    std::vector<DesignSpec> out;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty())
            continue;
        auto d = designSpecByName(item);
        if (!d)
            return makeError(d.error());
        for (const DesignSpec& seen : out)
            if (seen.label() == d->label())
                return makeError(fmt::format("design '{}' named twice", item));
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
