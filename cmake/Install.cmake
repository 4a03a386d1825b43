# SPDX-License-Identifier: MIT
# `cmake --install`: headers, static libraries, the `tgraph` binary, the CMake package with one
# component per library (find_package(tgraph COMPONENTS capture) -> tgraph::capture and
# tgraph::graph, finding only their dependencies; without COMPONENTS: every component built)
# and tgraph.pc for pkg-config users of the capture API.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(TGRAPH_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/tgraph"
    CACHE STRING "Where the CMake package files go (relative to the prefix)")

# How the package config finds again each imported target that a library links. The libraries
# are static, so their private dependencies are link dependencies of the consumer: every
# imported target in a link interface must be listed here (configuration stops otherwise).
set(_tgraph_find_Threads::Threads "find_package(Threads QUIET)\nset(_ok \${Threads_FOUND})")
set(_tgraph_find_ZLIB::ZLIB "find_package(ZLIB QUIET)\nset(_ok \${ZLIB_FOUND})")
set(_tgraph_find_nlohmann_json::nlohmann_json
    "find_package(nlohmann_json 3.10 QUIET CONFIG)\nset(_ok \${nlohmann_json_FOUND})")
set(_tgraph_find_TBB::tbb "find_package(TBB QUIET CONFIG)\nset(_ok \${TBB_FOUND})")
set(_tgraph_find_OpenMP::OpenMP_CXX
    "find_package(OpenMP QUIET COMPONENTS CXX)\nset(_ok \${OpenMP_CXX_FOUND})")
set(_tgraph_find_Eigen3::Eigen "find_package(Eigen3 3.4 QUIET CONFIG)\nset(_ok \${Eigen3_FOUND})")
set(_tgraph_find_MPI::MPI_CXX "find_package(MPI QUIET COMPONENTS CXX)\nset(_ok \${MPI_CXX_FOUND})")
# What to install to get them (the message of a failed find_package(tgraph)).
set(_tgraph_debian_Threads::Threads "libc6-dev")
set(_tgraph_debian_ZLIB::ZLIB "zlib1g-dev")
set(_tgraph_debian_nlohmann_json::nlohmann_json "nlohmann-json3-dev")
set(_tgraph_debian_TBB::tbb "libtbb-dev")
set(_tgraph_debian_OpenMP::OpenMP_CXX "g++ (libgomp)")
set(_tgraph_debian_Eigen3::Eigen "libeigen3-dev")
set(_tgraph_debian_MPI::MPI_CXX "libopenmpi-dev")
set(_tgraph_debian_PkgConfig::HWLOC "libhwloc-dev")
set(_tgraph_debian_PkgConfig::STARPU "libstarpu-dev")
set(_tgraph_debian_PkgConfig::STARPUMPI "libstarpu-dev")
set(_tgraph_debian_PkgConfig::GRAPHVIZ "libgraphviz-dev")
set(_tgraph_debian_PkgConfig::CAIRO "libcairo2-dev")
set(_tgraph_debian_PkgConfig::SIMGRID "libsimgrid-dev")
set(_tgraph_debian_PkgConfig::ODE "libode-dev")

# The modules, as library targets tgraph_<module> in folder <folder>, in dependency order.
set(_tgraph_modules "")
foreach(pair graph:libgraph capture:capture model:model partition:partition replay:replay
             explain:explain viz:viz samples:samples measure:measure ode:ode mpi:mpi
             experiment:experiment)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 module)
  list(GET pair 1 folder)
  if(TARGET tgraph_${module})
    list(APPEND _tgraph_modules ${module})
    set(_tgraph_folder_${module} ${folder})
  endif()
endforeach()

# _tgraph_component_dependencies(MODULE): what the component's targets link, split into the
# components they need (_tgraph_needs_<module>) and the imported targets of other packages
# (_tgraph_imports_<module>). tgraph_options goes with graph; tgraph_metis and tgraph_scotch
# (interface targets naming Debian's libraries) go with partition.
function(_tgraph_component_dependencies module)
  set(targets tgraph_${module})
  if(module STREQUAL "graph")
    list(APPEND targets tgraph_options)
  elseif(module STREQUAL "partition")
    list(APPEND targets tgraph_metis tgraph_scotch)
  endif()
  set(needs "")
  set(imports "")
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    if(type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(links ${target} INTERFACE_LINK_LIBRARIES)
    else()
      get_target_property(links ${target} LINK_LIBRARIES)
    endif()
    foreach(link IN LISTS links)
      if(NOT link MATCHES "([A-Za-z0-9_]+::[A-Za-z0-9_]+)")
        continue()  # a library file, or nothing
      endif()
      set(link "${CMAKE_MATCH_1}")
      if(link MATCHES "^tgraph::(.*)$")
        if(CMAKE_MATCH_1 IN_LIST _tgraph_modules AND NOT CMAKE_MATCH_1 STREQUAL module)
          list(APPEND needs ${CMAKE_MATCH_1})
        endif()
        continue()  # options, metis, scotch: in this component's export set
      endif()
      if(NOT DEFINED _tgraph_find_${link} AND NOT link MATCHES "^PkgConfig::")
        message(FATAL_ERROR "cmake/Install.cmake: tgraph_${module} links ${link}; say how the "
                            "package config finds it again (_tgraph_find_${link})")
      endif()
      list(APPEND imports ${link})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES needs)
  list(REMOVE_DUPLICATES imports)
  set(_tgraph_needs_${module} "${needs}" PARENT_SCOPE)
  set(_tgraph_imports_${module} "${imports}" PARENT_SCOPE)
endfunction()

set(TGRAPH_PACKAGE_COMPONENTS "")
set(_tgraph_emitted "")
set(_tgraph_before "")
foreach(module IN LISTS _tgraph_modules)
  _tgraph_component_dependencies(${module})
  foreach(need IN LISTS _tgraph_needs_${module})
    if(NOT need IN_LIST _tgraph_before)  # the package config loads in this order
      message(FATAL_ERROR "cmake/Install.cmake: ${module} links ${need}, listed after it")
    endif()
  endforeach()
  list(APPEND _tgraph_before ${module})
  set(exported tgraph_${module})
  if(module STREQUAL "graph")
    list(APPEND exported tgraph_options)
    set_target_properties(tgraph_options PROPERTIES EXPORT_NAME options)
  elseif(module STREQUAL "partition")
    foreach(dep metis scotch)
      set_target_properties(tgraph_${dep} PROPERTIES EXPORT_NAME ${dep})
      list(APPEND exported tgraph_${dep})
    endforeach()
  endif()
  set_target_properties(tgraph_${module} PROPERTIES EXPORT_NAME ${module})
  # The module's public include folder is in the source tree: seen from the build only; the
  # installed target finds the same headers under <prefix>/include.
  get_target_property(_dirs tgraph_${module} INTERFACE_INCLUDE_DIRECTORIES)
  set(_wrapped "")
  foreach(dir IN LISTS _dirs)
    if(dir MATCHES "^\\$<")
      list(APPEND _wrapped "${dir}")  # already wrapped (generated headers)
    else()
      list(APPEND _wrapped "$<BUILD_INTERFACE:${dir}>")
    endif()
  endforeach()
  list(APPEND _wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  list(REMOVE_DUPLICATES _wrapped)
  set_target_properties(tgraph_${module} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_wrapped}")
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/${_tgraph_folder_${module}}/include/"
          DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.hpp")
  # Generated public headers (tgraph/version.hpp).
  if(EXISTS "${PROJECT_BINARY_DIR}/${_tgraph_folder_${module}}/include")
    install(DIRECTORY "${PROJECT_BINARY_DIR}/${_tgraph_folder_${module}}/include/"
            DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.hpp")
  endif()
  install(TARGETS ${exported} EXPORT tgraph-${module}-targets
          ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
          LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
  install(EXPORT tgraph-${module}-targets NAMESPACE tgraph::
          DESTINATION "${TGRAPH_INSTALL_CMAKEDIR}")

  # The component's part of tgraphConfig.cmake: the components it needs, and how to find
  # each imported target it links (the code sets _ok).
  string(APPEND TGRAPH_PACKAGE_COMPONENTS
         "set(_tgraph_needs_${module} \"${_tgraph_needs_${module}}\")\n"
         "set(_tgraph_imports_${module} \"${_tgraph_imports_${module}}\")\n")
  foreach(import IN LISTS _tgraph_imports_${module})
    if(import IN_LIST _tgraph_emitted)
      continue()
    endif()
    list(APPEND _tgraph_emitted ${import})
    if(import MATCHES "^PkgConfig::(.*)$")
      set(name "${CMAKE_MATCH_1}")
      get_property(pc_modules GLOBAL PROPERTY TGRAPH_PKG_CONFIG_${name})
      if(NOT pc_modules AND DEFINED __pkg_config_arguments_${name})
        # Made by a plain pkg_check_modules: its arguments (an internal cache entry of
        # FindPkgConfig) less the keywords are the modules.
        set(pc_modules ${__pkg_config_arguments_${name}})
        list(REMOVE_ITEM pc_modules REQUIRED QUIET IMPORTED_TARGET GLOBAL NO_CMAKE_PATH
             NO_CMAKE_ENVIRONMENT_PATH)
      endif()
      if(NOT pc_modules)
        message(FATAL_ERROR "cmake/Install.cmake: tgraph_${module} links ${import}, not made "
                            "by tgraph_pkg_config (cmake/Dependencies.cmake)")
      endif()
      string(REPLACE ";" " " pc_modules "${pc_modules}")
      set(_tgraph_find_${import} "find_package(PkgConfig QUIET)\nset(_ok FALSE)
if(PkgConfig_FOUND)
  pkg_check_modules(${name} QUIET IMPORTED_TARGET ${pc_modules})
  set(_ok \${${name}_FOUND})
endif()")
      if(NOT DEFINED _tgraph_debian_${import})
        set(_tgraph_debian_${import} "pkg-config ${pc_modules}")
      endif()
    endif()
    string(MAKE_C_IDENTIFIER "${import}" id)
    string(APPEND TGRAPH_PACKAGE_COMPONENTS
           "macro(_tgraph_find_${id})\n${_tgraph_find_${import}}\nendmacro()\n"
           "set(_tgraph_debian_${import} \"${_tgraph_debian_${import}}\")\n")
  endforeach()
endforeach()
if(TARGET tgraph)
  install(TARGETS tgraph RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
endif()
if(TARGET tgraph-mpi)
  install(TARGETS tgraph-mpi RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
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
