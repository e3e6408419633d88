# Install and export (docs/user_guide.md, "Install and use from another project"):
#   cmake --install build --prefix P
# installs the public headers (P/include/vdyn/...), the vdyn libraries (P/lib),
# the data files (P/share/vdyn/data, found at run time from the installed
# library, see dataSearchPath() in vdyn/core/params.h), the `vdyn` program and
# the CMake package P/lib/cmake/vdyn (vdynConfig.cmake, vdynConfigVersion.cmake,
# vdynTargets.cmake): find_package(vdyn CONFIG REQUIRED) gives vdyn::core,
# vdyn::tire, ..., vdyn::vehicles and the umbrella vdyn::vdyn. In this build the
# same names exist as aliases, so code written against the package also builds
# with add_subdirectory.
include(CMakePackageConfigHelpers)

# Every library a user may link, in dependency order. A name here that is not a
# target is a configure error (the list cannot drift from the build), except
# vdyn_sweep_mpi, which exists only when CMake finds MPI.
set(VDYN_EXPORTED_LIBRARIES
  vdyn_core vdyn_sweep vdyn_sweep_mpi
  vdyn_magic_formula vdyn_tire vdyn_steering vdyn_speed vdyn_forces vdyn_path vdyn_path_control
  vdyn_linear_ratio vdyn_rear_steer vdyn_steady_state vdyn_steering_ratio vdyn_sensitivity
  vdyn_plugins vdyn_analyses
  vdyn_handling vdyn_vehicles vdyn_handling_vehicles vdyn_standard
)

# Consumers must not compile vdyn or Simbody headers with NDEBUG (Debian's
# Simbody was built without it; config.h turns it into a compile error). -UNDEBUG
# comes after CMake's configuration flags (-O3 -DNDEBUG for Release) on the
# command line, so it wins. Simbody 3.7's headers do not compile as C++20: the
# project is C++17, and so must its users be (stated in docs/user_guide.md, "Install and use from another project").
target_compile_options(vdyn_core INTERFACE -UNDEBUG)
target_compile_features(vdyn_core PUBLIC cxx_std_17)

add_library(vdyn_all INTERFACE)
set_target_properties(vdyn_all PROPERTIES EXPORT_NAME vdyn)
add_library(vdyn::vdyn ALIAS vdyn_all)

set(_vdyn_installed_targets vdyn_all)
foreach(t IN LISTS VDYN_EXPORTED_LIBRARIES)
  if(NOT TARGET ${t})
    if(t STREQUAL "vdyn_sweep_mpi")
      continue()
    endif()
    message(FATAL_ERROR "VDYN_EXPORTED_LIBRARIES names ${t}, which is not a target of this build")
  endif()
  string(REGEX REPLACE "^vdyn_" "" short ${t})
  set_target_properties(${t} PROPERTIES EXPORT_NAME ${short}
                                        VERSION ${PROJECT_VERSION}
                                        SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  add_library(vdyn::${short} ALIAS ${t})
  target_link_libraries(vdyn_all INTERFACE ${t})
  # Include folders of the source tree: installed under P/include (every public
  # folder holds vdyn/<part>/...), used from the source tree by this build.
  get_target_property(dirs ${t} INTERFACE_INCLUDE_DIRECTORIES)
  if(NOT dirs)
    set(dirs "")
  endif()
  set(wrapped "")
  foreach(d IN LISTS dirs)
    if(d MATCHES "^(${CMAKE_SOURCE_DIR}|${CMAKE_BINARY_DIR})")
      install(DIRECTORY ${d}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
      list(APPEND wrapped "$<BUILD_INTERFACE:${d}>")
    else()
      list(APPEND wrapped "${d}")
    endif()
  endforeach()
  list(APPEND wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  list(REMOVE_DUPLICATES wrapped)
  set_target_properties(${t} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${wrapped}")
  list(APPEND _vdyn_installed_targets ${t})
endforeach()

install(TARGETS ${_vdyn_installed_targets} EXPORT vdynTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The `vdyn` program (studies/vdyn), exported as vdyn::cli.
if(TARGET vdyn)
  set_target_properties(vdyn PROPERTIES EXPORT_NAME cli)
  install(TARGETS vdyn EXPORT vdynTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# The data files, with the chapter scenes (data/scenes/).
install(DIRECTORY ${CMAKE_SOURCE_DIR}/vehicles/data/ DESTINATION ${VDYN_INSTALL_DATADIR})

set(VDYN_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/vdyn)
install(EXPORT vdynTargets NAMESPACE vdyn:: DESTINATION ${VDYN_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/vdynConfig.cmake.in
  ${CMAKE_BINARY_DIR}/cmake/vdynConfig.cmake
  INSTALL_DESTINATION ${VDYN_INSTALL_CMAKEDIR}
  PATH_VARS VDYN_INSTALL_DATADIR)
# 0.x: a minor version may change the API, so only the same major.minor matches.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/cmake/vdynConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/vdynConfig.cmake ${CMAKE_BINARY_DIR}/cmake/vdynConfigVersion.cmake
  DESTINATION ${VDYN_INSTALL_CMAKEDIR})
