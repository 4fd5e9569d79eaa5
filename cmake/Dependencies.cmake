# Every dependency is a Debian 12 package; scripts/setup.sh installs them.
# Debian ships OpenVDB's Find module (not a config file) beside the library.
list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")

find_package(Threads REQUIRED)
find_package(OpenMP REQUIRED)
find_package(TBB REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(CGAL 5.5 REQUIRED)
find_package(assimp REQUIRED)
find_package(embree 3 REQUIRED)
find_package(OpenVDB REQUIRED COMPONENTS openvdb)
find_package(GTest REQUIRED)
find_package(fmt REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(CLI11 2 REQUIRED CONFIG)
find_package(ZLIB REQUIRED)

# CGAL must not be configured for Debug-only assertions in Release builds.
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)

# Optional: with OpenMPI the DEM splits over ranks (dem/mpi_exchange.hpp); without it diefill
# runs on one process as before.
find_package(MPI COMPONENTS CXX)
