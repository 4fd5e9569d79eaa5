#pragma once
// What a ring filled with capsule clumps must report, one process or split over ranks
// (test_pipeline.cpp, test_mpi_cli.cpp): none lost, the census adds up, several spheres a grain,
// and the grains' volume their true one (volume-equivalent spheres), not their members'.
#include <gtest/gtest.h>

#include <cstdint>
#include <numbers>
#include <nlohmann/json.hpp>

namespace test {

inline void expect_clump_fill_census(const nlohmann::json& report) {
  const nlohmann::json& p = report["particles"];
  EXPECT_EQ(p["lost"].get<std::int64_t>(), 0);
  EXPECT_GT(p["in_cavity"].get<std::int64_t>(), 100);
  EXPECT_EQ(p["inserted"].get<std::int64_t>(),
            p["in_cavity"].get<std::int64_t>() + p["in_shoe"].get<std::int64_t>() + p["elsewhere"].get<std::int64_t>() +
                p["spilled"].get<std::int64_t>());
  EXPECT_GT(report["powder"]["spheres_per_grain"].get<int>(), 1);
  const double d = report["powder"]["grain_diameter_m"].get<double>();
  const double expected = double(p["inserted"].get<std::int64_t>()) * std::numbers::pi / 6 * d * d * d;
  EXPECT_NEAR(report["powder"]["total_grain_volume_m3"].get<double>(), expected, 1e-9 * expected);
}

}  // namespace test
