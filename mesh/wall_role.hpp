#pragma once
// What a wall mesh is to the grains (a light header: the scene reads it without the mesh stage).
#include <array>
#include <string_view>

#include "core/choice.hpp"

namespace mesh {

// cavity: the part's shape, open at the die table (the tool is the table minus it);
// tool: the solid itself (die body, punch, obstacle); container: a closed vessel whose inside
// holds the grains (the LIGGGHTS benchmark's cylinder).
enum class WallRole { cavity, tool, container };
inline constexpr std::array<diefill::Choice<WallRole>, 3> wall_roles = {
    {{"cavity", WallRole::cavity}, {"tool", WallRole::tool}, {"container", WallRole::container}}};
WallRole parse_role(std::string_view text, std::string_view field);  // also "solid" for a tool
inline std::string_view role_name(WallRole role) { return diefill::choice_name(wall_roles, role); }

}  // namespace mesh
