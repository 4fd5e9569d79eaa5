#pragma once
// The choices of the scene that no other module owns, as enums with their names: read once from
// the scene's text (scene/pipeline_scene.cpp) or a command's flag, and acted on by the stage.
#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.hpp"

namespace scene {

// [density] method: the volume of each grain split exactly among the voxels, or a Gaussian kernel
// (postprocess/density.hpp).
enum class DensityMethod { exact, gaussian };
inline constexpr std::array<std::pair<std::string_view, DensityMethod>, 2> density_methods = {
    {{"exact", DensityMethod::exact}, {"gaussian", DensityMethod::gaussian}}};

// [fem] the hand-off to compaction FEM (docs/INTERFACE.md, "FEM hand-off"): C3D4 or C3D10
// elements, or none; and the worked example pressed in CalculiX, or not.
enum class FemElements { linear, quadratic, none };
inline constexpr std::array<std::pair<std::string_view, FemElements>, 3> fem_element_kinds = {
    {{"linear", FemElements::linear}, {"quadratic", FemElements::quadratic}, {"none", FemElements::none}}};
enum class FemCompaction { calculix, none };
inline constexpr std::array<std::pair<std::string_view, FemCompaction>, 2> fem_compactions = {
    {{"calculix", FemCompaction::calculix}, {"none", FemCompaction::none}}};

// The value named `text` in a choice's table; InputError naming `field` when it names none.
template <class Value, std::size_t N>
Value parse_choice(const std::array<std::pair<std::string_view, Value>, N>& table, std::string_view text, std::string_view field) {
  std::string names;
  for (const auto& [name, v] : table) {
    if (name == text) return v;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  throw diefill::InputError(std::string(field), std::string(text), "is not one of its choices", "Use one of: " + names);
}

// The name of a choice's value in its table.
template <class Value, std::size_t N>
constexpr std::string_view choice_name(const std::array<std::pair<std::string_view, Value>, N>& table, Value value) {
  for (const auto& [name, v] : table)
    if (v == value) return name;
  return {};
}

}  // namespace scene
