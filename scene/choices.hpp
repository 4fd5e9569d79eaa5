#pragma once
// The choices of the scene that no other module owns, as enums with their names (core/choice.hpp):
// read once from the scene's text (scene/pipeline_scene.cpp) or a command's flag, and acted on by
// the stage.
#include <array>

#include "core/choice.hpp"

namespace scene {

// [density] method: the volume of each grain split exactly among the voxels, or a Gaussian kernel
// (postprocess/density.hpp).
enum class DensityMethod { exact, gaussian };
inline constexpr std::array<diefill::Choice<DensityMethod>, 2> density_methods = {
    {{"exact", DensityMethod::exact}, {"gaussian", DensityMethod::gaussian}}};

// [fem] the hand-off to compaction FEM (docs/INTERFACE.md, "FEM hand-off"): C3D4 or C3D10
// elements, or none; and the worked example pressed in CalculiX, or not.
enum class FemElements { linear, quadratic, none };
inline constexpr std::array<diefill::Choice<FemElements>, 3> fem_element_kinds = {
    {{"linear", FemElements::linear}, {"quadratic", FemElements::quadratic}, {"none", FemElements::none}}};
enum class FemCompaction { calculix, none };
inline constexpr std::array<diefill::Choice<FemCompaction>, 2> fem_compactions = {
    {{"calculix", FemCompaction::calculix}, {"none", FemCompaction::none}}};

}  // namespace scene
