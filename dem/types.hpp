#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "core/huge_pages.hpp"

namespace dem {
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
// What the state keeps of a grain pair between steps (its contact history, the positions at the
// last list build) is stored in single precision: computed in double, rounded once when stored
// (docs/ARCHITECTURE.md, "Model and state"; the bytes in docs/PERFORMANCE.md).
using Vec3f = Eigen::Vector3f;

// The State's arrays.
template <class T>
using Array = std::vector<T, diefill::HugePageAllocator<T>>;

}  // namespace dem
