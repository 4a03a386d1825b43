# SPDX-License-Identifier: MIT
# `cmake --install`: headers, static libraries, the `tgraph` binary, the CMake package
# (find_package(tgraph) -> tgraph::graph, tgraph::capture, tgraph::partition, tgraph::replay,
# tgraph::viz, tgraph::samples, tgraph::experiment, as built) and tgraph.pc for pkg-config users of the capture API.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(TGRAPH_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/tgraph"
    CACHE STRING "Where the CMake package files go (relative to the prefix)")

# Library targets and their folders, in dependency order. tgraph_options carries C++20 to
# consumers; tgraph_metis and tgraph_scotch are the link-only dependencies of the static
# partition library.
set(_tgraph_exported tgraph_options)
set(_tgraph_modules "")
foreach(pair graph:libgraph capture:capture partition:partition replay:replay viz:viz
             samples:samples experiment:experiment)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 module)
  list(GET pair 1 folder)
  if(NOT TARGET tgraph_${module})
    continue()
  endif()
  list(APPEND _tgraph_modules ${module})
  list(APPEND _tgraph_exported tgraph_${module})
  set_target_properties(tgraph_${module} PROPERTIES EXPORT_NAME ${module})
  # The module's public include folder is in the source tree: seen from the build only; the
  # installed target finds the same headers under <prefix>/include.
  get_target_property(_dirs tgraph_${module} INTERFACE_INCLUDE_DIRECTORIES)
  set(_wrapped "")
  foreach(dir IN LISTS _dirs)
    list(APPEND _wrapped "$<BUILD_INTERFACE:${dir}>")
  endforeach()
  list(APPEND _wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  set_target_properties(tgraph_${module} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_wrapped}")
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/${folder}/include/"
          DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.hpp")
endforeach()
foreach(dep metis scotch)
  if(TARGET tgraph_${dep} AND TARGET tgraph_partition)
    set_target_properties(tgraph_${dep} PROPERTIES EXPORT_NAME ${dep})
    list(APPEND _tgraph_exported tgraph_${dep})
  endif()
endforeach()
set_target_properties(tgraph_options PROPERTIES EXPORT_NAME options)

install(TARGETS ${_tgraph_exported} EXPORT tgraphTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
if(TARGET tgraph)
  install(TARGETS tgraph RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
endif()
install(EXPORT tgraphTargets NAMESPACE tgraph:: DESTINATION "${TGRAPH_INSTALL_CMAKEDIR}")

# What the package config must find again: the libraries are static, so their private
# dependencies are link dependencies of the consumer.
set(TGRAPH_PACKAGE_STARPU OFF)
if(TARGET PkgConfig::STARPU)
  set(TGRAPH_PACKAGE_STARPU ON)
endif()
set(TGRAPH_PACKAGE_SIMGRID OFF)
if(TARGET tgraph_partition)
  get_target_property(_tgraph_partition_defs tgraph_partition INTERFACE_COMPILE_DEFINITIONS)
  if(_tgraph_partition_defs MATCHES "TGRAPH_HAVE_SIMGRID")
    set(TGRAPH_PACKAGE_SIMGRID ON)
  endif()
endif()
set(TGRAPH_PACKAGE_GRAPHVIZ OFF)
if(TARGET tgraph_viz)
  set(TGRAPH_PACKAGE_GRAPHVIZ ON)
endif()
set(TGRAPH_PACKAGE_EIGEN OFF)
if(TARGET tgraph_samples)
  set(TGRAPH_PACKAGE_EIGEN ON)
endif()
set(TGRAPH_PACKAGE_MODULES "${_tgraph_modules}")
configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/tgraphConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/tgraphConfig.cmake"
                              INSTALL_DESTINATION "${TGRAPH_INSTALL_CMAKEDIR}")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/tgraphConfigVersion.cmake"
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/tgraphConfig.cmake"
              "${PROJECT_BINARY_DIR}/tgraphConfigVersion.cmake"
        DESTINATION "${TGRAPH_INSTALL_CMAKEDIR}")

# pkg-config: the capture API and the data model (static libraries, zlib for the trace
# files). The prefix is found from the .pc file's own place, so --prefix at install works.
file(RELATIVE_PATH TGRAPH_PC_TO_PREFIX "/root/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/root")
configure_file("${PROJECT_SOURCE_DIR}/cmake/tgraph.pc.in" "${PROJECT_BINARY_DIR}/tgraph.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/tgraph.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
