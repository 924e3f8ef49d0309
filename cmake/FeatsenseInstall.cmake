# `cmake --install build --prefix P`: the libraries of the mapping engine and the rooms it
# needs, their public headers and featsenseConfig.cmake with exported targets, so that another
# CMake project says find_package(featsense) and links featsense::mapping (the Mapper), and
# featsense::mesh / featsense::viewer_export to mesh a map and write it (docs/LIBRARY.md).
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)

set(FEATSENSE_INSTALLED_TARGETS
  featsense_config featsense_opencv featsense_slam_core featsense_slam_trajectory
  featsense_slam_features featsense_slam_odometry featsense_slam_refine featsense_slam_loops
  featsense_slam_io featsense_tsdf featsense_storage featsense_mapping featsense_mesh_types
  featsense_mesh featsense_viewer_export)

# The public headers of each installed room, merged under one include/ (every header lives
# under include/featsense/<room>/, so they never collide).
set(FEATSENSE_PUBLIC_HEADER_DIRS
  config/include slam/core/include slam/trajectory/include slam/features/include
  slam/odometry/include slam/refine/include slam/loops/include slam/io/include tsdf/include
  storage/include slam/mapping/include mesh/include viewer_export/include)

foreach(target IN LISTS FEATSENSE_INSTALLED_TARGETS)
  # Include directories in the source tree hold for the build; installed, the headers are in
  # the prefix's include/.
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(wrapped "")
  if(dirs)
    foreach(dir IN LISTS dirs)
      if(dir MATCHES "^${PROJECT_SOURCE_DIR}" OR dir MATCHES "^${PROJECT_BINARY_DIR}")
        list(APPEND wrapped "$<BUILD_INTERFACE:${dir}>")
      else()
        list(APPEND wrapped "${dir}")
      endif()
    endforeach()
  endif()
  list(APPEND wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${wrapped}")
  # featsense_slam_core -> featsense::slam_core, as inside the build.
  string(REGEX REPLACE "^featsense_" "" export_name ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  # Installed shared libraries find each other beside themselves.
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "SHARED_LIBRARY")
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "$ORIGIN")
  endif()
endforeach()

install(TARGETS ${FEATSENSE_INSTALLED_TARGETS} EXPORT featsenseTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The program too, with the libraries it loads (its own app library, the simulator's).
set_target_properties(featsense PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
foreach(target featsense_app_core featsense_slam_sim)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "SHARED_LIBRARY")
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "$ORIGIN")
    install(TARGETS ${target} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  endif()
endforeach()
install(TARGETS featsense RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(dir IN LISTS FEATSENSE_PUBLIC_HEADER_DIRS)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
install(EXPORT featsenseTargets NAMESPACE featsense::
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/featsense)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/featsenseConfig.cmake.in
  ${PROJECT_BINARY_DIR}/featsenseConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/featsense)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/featsenseConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/featsenseConfig.cmake
              ${PROJECT_BINARY_DIR}/featsenseConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/featsense)
