#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "core/huge_pages.hpp"

namespace dem {
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// The State's arrays.
template <class T>
using Array = std::vector<T, diefill::HugePageAllocator<T>>;

}  // namespace dem
