#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dem {
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
}  // namespace dem
