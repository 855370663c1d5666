// The world models of Quake III / OpenArena item entities (the game's bg_itemlist): what a
// level places for the player to pick up — weapons, ammunition, health, armour, powerups,
// holdables and flags. These are the interactive objects of the paper's static design (§2,
// Table 1), where the level's brushes are its background.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace qvr::detail {

struct QuakeItemModel {
    std::vector<std::string> md3_paths;  // every part the game draws (health: cross and sphere)
    float scale = 1.0f;                  // the client draws weapons 1.5× (CG_Item)
};

// Empty md3_paths when the class is not an item drawn in the world.
QuakeItemModel quakeItemModel(std::string_view classname);

}  // namespace qvr::detail
