#include "quake_items.h"

#include <array>
#include <utility>

#include <fmt/format.h>

namespace qvr::detail {

namespace {

// Class suffix → the directory and file under models/weapons2 or models/powerups/ammo.
constexpr std::array<std::pair<std::string_view, std::string_view>, 12> kWeapons = {{
    {"gauntlet", "gauntlet"},
    {"shotgun", "shotgun"},
    {"machinegun", "machinegun"},
    {"grenadelauncher", "grenadel"},
    {"rocketlauncher", "rocketl"},
    {"lightning", "lightning"},
    {"railgun", "railgun"},
    {"plasmagun", "plasma"},
    {"bfg", "bfg"},
    {"nailgun", "nailgun"},
    {"prox_launcher", "proxmine"},
    {"chaingun", "vulcan"},
}};
constexpr std::array<std::pair<std::string_view, std::string_view>, 11> kAmmo = {{
    {"shells", "shotgunam"},
    {"bullets", "machinegunam"},
    {"grenades", "grenadeam"},
    {"cells", "plasmaam"},
    {"lightning", "lightningam"},
    {"rockets", "rocketam"},
    {"slugs", "railgunam"},
    {"bfg", "bfgam"},
    {"nails", "nailgunam"},
    {"mines", "proxmineam"},
    {"belt", "chaingunam"},
}};
// Full class name → model paths below models/.
constexpr std::array<std::pair<std::string_view, std::string_view>, 14> kOthers = {{
    {"item_armor_shard", "powerups/armor/shard"},
    {"item_armor_combat", "powerups/armor/armor_yel"},
    {"item_armor_body", "powerups/armor/armor_red"},
    {"item_quad", "powerups/instant/quad"},
    {"item_enviro", "powerups/instant/enviro"},
    {"item_haste", "powerups/instant/haste"},
    {"item_invis", "powerups/instant/invis"},
    {"item_regen", "powerups/instant/regen"},
    {"item_flight", "powerups/instant/flight"},
    {"holdable_teleporter", "powerups/holdable/teleporter"},
    {"holdable_medkit", "powerups/holdable/medkit"},
    {"team_CTF_redflag", "flags/r_flag"},
    {"team_CTF_blueflag", "flags/b_flag"},
    {"team_CTF_neutralflag", "flags/n_flag"},
}};

template <size_t N>
std::string_view find(const std::array<std::pair<std::string_view, std::string_view>, N>& table,
                      std::string_view key) {
    for (const auto& [k, v] : table)
        if (k == key)
            return v;
    return {};
}

QuakeItemModel health(std::string_view size) {
    return {{fmt::format("models/powerups/health/{}_cross.md3", size),
             fmt::format("models/powerups/health/{}_sphere.md3", size)},
            1.0f};
}

}  // namespace

QuakeItemModel quakeItemModel(std::string_view classname) {
    constexpr std::string_view kWeapon = "weapon_", kAmmoPrefix = "ammo_";
    if (classname.starts_with(kWeapon)) {
        const std::string_view dir = find(kWeapons, classname.substr(kWeapon.size()));
        if (dir.empty())
            return {};
        return {{fmt::format("models/weapons2/{0}/{0}.md3", dir)}, 1.5f};
    }
    if (classname.starts_with(kAmmoPrefix)) {
        const std::string_view file = find(kAmmo, classname.substr(kAmmoPrefix.size()));
        if (file.empty())
            return {};
        return {{fmt::format("models/powerups/ammo/{}.md3", file)}, 1.0f};
    }
    if (classname == "item_health")
        return health("medium");
    if (classname == "item_health_small")
        return health("small");
    if (classname == "item_health_large")
        return health("large");
    if (classname == "item_health_mega")
        return health("mega");
    const std::string_view path = find(kOthers, classname);
    if (path.empty())
        return {};
    return {{fmt::format("models/{}.md3", path)}, 1.0f};
}

}  // namespace qvr::detail
