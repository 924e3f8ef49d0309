# Every dependency comes from Debian's packages through find_package; nothing is downloaded.
find_package(Threads REQUIRED)
# TBB first: otherwise OpenVDB's FindTBB and Ceres' SuiteSparse lookup define the same targets.
find_package(TBB CONFIG REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(spdlog CONFIG REQUIRED)
find_package(nlohmann_json 3 CONFIG REQUIRED)
find_package(BZip2 REQUIRED)
# Serial HDF5's C API: the global map store (storage/) and the mesh navigation export
# (viewer_export/src/mesh_nav_h5_writer.cpp); zlib for the store journal's records.
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(ZLIB REQUIRED)
# OpenVDB (storage/src/vdb_io.cpp only): Debian installs its find module beside its CMake files.
list(APPEND CMAKE_MODULE_PATH /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
find_package(liblzf CONFIG REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
# ROS 2 bags (sqlite3 storage) and MCAP's zstd chunks (slam/io).
find_package(SQLite3 REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
# `featsense view`'s HTTP server (app/view_server.cpp) and its tests' client: Debian builds
# cpp-httplib as a library whose header must see the same feature macros, which its pkg-config
# file gives.
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
# The simulator: Embree casts the rays (slam/sim); assimp reads mesh files (viewer_export), the
# simulator's scene files among them.
find_package(embree 3 CONFIG REQUIRED)
find_package(assimp CONFIG REQUIRED)
# CGAL 5.5 is header-only; its imported target keeps its headers SYSTEM so that their warnings
# never fail our build. Only mesh/src/closest_point_query.cpp includes it.
find_package(CGAL CONFIG REQUIRED)
# Levels of detail of tiled meshes: meshoptimizer's simplifier (mesh/src/mesh_simplification.cpp).
find_package(meshoptimizer CONFIG REQUIRED)

# The front end (slam/features, slam/odometry): OpenCV's core and imgproc for the intensity
# image (Debian's two packages ship no CMake config, and the full libopencv-dev pulls in about
# 160 packages), Ceres for the registration, nanoflann for nearest neighbours.
find_path(FEATSENSE_OPENCV_INCLUDE_DIR opencv2/imgproc.hpp PATH_SUFFIXES opencv4 REQUIRED)
find_library(FEATSENSE_OPENCV_CORE_LIBRARY opencv_core REQUIRED)
find_library(FEATSENSE_OPENCV_IMGPROC_LIBRARY opencv_imgproc REQUIRED)
add_library(featsense_opencv INTERFACE)
add_library(featsense::opencv ALIAS featsense_opencv)
target_include_directories(featsense_opencv SYSTEM INTERFACE ${FEATSENSE_OPENCV_INCLUDE_DIR})
target_link_libraries(featsense_opencv INTERFACE ${FEATSENSE_OPENCV_IMGPROC_LIBRARY}
                                                 ${FEATSENSE_OPENCV_CORE_LIBRARY})
find_package(Ceres CONFIG REQUIRED)
find_package(nanoflann CONFIG REQUIRED)
