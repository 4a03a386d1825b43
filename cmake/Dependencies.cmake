# SPDX-License-Identifier: MIT
# Every dependency comes from a Debian package; none is vendored.
find_package(PkgConfig REQUIRED)

# tgraph_pkg_config(NAME [OPTIONAL] MODULES m...): pkg_check_modules with a GLOBAL imported
# target PkgConfig::NAME, whose pkg-config modules are remembered: the installed package
# config (cmake/Install.cmake) finds the same target again for the libraries that link it.
macro(tgraph_pkg_config name)
  cmake_parse_arguments(_tgraph_pc "OPTIONAL" "" "MODULES" ${ARGN})
  if(_tgraph_pc_OPTIONAL)
    pkg_check_modules(${name} QUIET IMPORTED_TARGET GLOBAL ${_tgraph_pc_MODULES})
  else()
    pkg_check_modules(${name} REQUIRED IMPORTED_TARGET GLOBAL ${_tgraph_pc_MODULES})
  endif()
  set_property(GLOBAL PROPERTY TGRAPH_PKG_CONFIG_${name} "${_tgraph_pc_MODULES}")
endmacro()

# tgraph_optional_pkg(TARGET NAME MODULE m WHAT w DEBIAN d DEFINE D [PUBLIC] [SOURCES s...]
#                     FOUND text MISSING text): an optional dependency that one module uses
# privately. When pkg-config finds m, TARGET compiles SOURCES, links PkgConfig::NAME and
# defines D=1 (PUBLIC: also for what links TARGET, so that tests and tools can tell); a
# status line either way ("w <version> found: FOUND", "w (pkg-config m, Debian d) not
# found: MISSING"). The option TGRAPH_WITH_NAME (ON) set OFF leaves the dependency out even
# when it is installed (the demo's build folder, scripts/demo, builds without SimGrid).
macro(tgraph_optional_pkg target name)
  cmake_parse_arguments(_tgraph_opt "PUBLIC" "MODULE;WHAT;DEBIAN;DEFINE;FOUND;MISSING" "SOURCES"
                        ${ARGN})
  option(TGRAPH_WITH_${name} "Use ${_tgraph_opt_WHAT} when pkg-config finds it" ON)
  if(NOT TGRAPH_WITH_${name})
    message(STATUS "tgraph: ${_tgraph_opt_WHAT} left out (TGRAPH_WITH_${name}=OFF): "
                   "${_tgraph_opt_MISSING}")
  else()
    tgraph_pkg_config(${name} OPTIONAL MODULES ${_tgraph_opt_MODULE})
    if(${name}_FOUND)
      message(STATUS "tgraph: ${_tgraph_opt_WHAT} ${${name}_VERSION} found: ${_tgraph_opt_FOUND}")
      target_sources(${target} PRIVATE ${_tgraph_opt_SOURCES})
      target_link_libraries(${target} PRIVATE PkgConfig::${name})
      if(_tgraph_opt_PUBLIC)
        target_compile_definitions(${target} PUBLIC ${_tgraph_opt_DEFINE}=1)
      else()
        target_compile_definitions(${target} PRIVATE ${_tgraph_opt_DEFINE}=1)
      endif()
    else()
      message(STATUS "tgraph: ${_tgraph_opt_WHAT} (pkg-config ${_tgraph_opt_MODULE}, Debian "
                     "${_tgraph_opt_DEBIAN}) not found: ${_tgraph_opt_MISSING}")
    endif()
  endif()
endmacro()
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)
find_package(Eigen3 3.4 REQUIRED CONFIG)
find_package(nlohmann_json 3.10 REQUIRED CONFIG)
find_package(CLI11 REQUIRED CONFIG)
find_package(TBB REQUIRED CONFIG)
find_package(OpenMP REQUIRED COMPONENTS CXX)
tgraph_pkg_config(HWLOC MODULES hwloc)
tgraph_pkg_config(GRAPHVIZ MODULES libcgraph libgvc)

# METIS 5.1 ships neither pkg-config nor CMake files.
find_path(METIS_INCLUDE_DIR metis.h PATHS /usr/include NO_DEFAULT_PATH REQUIRED)
find_library(METIS_LIBRARY NAMES metis REQUIRED)
add_library(tgraph_metis INTERFACE)
add_library(tgraph::metis ALIAS tgraph_metis)
target_include_directories(tgraph_metis SYSTEM INTERFACE ${METIS_INCLUDE_DIR})
target_link_libraries(tgraph_metis INTERFACE ${METIS_LIBRARY})

# Scotch: include <scotch/scotch.h> only (never /usr/include/scotch itself, whose metis.h
# shadows METIS's); link scotch + scotcherr, never libscotchmetis*.
find_path(SCOTCH_INCLUDE_PARENT scotch/scotch.h REQUIRED)
find_library(SCOTCH_LIBRARY NAMES scotch REQUIRED)
find_library(SCOTCHERR_LIBRARY NAMES scotcherr REQUIRED)
add_library(tgraph_scotch INTERFACE)
add_library(tgraph::scotch ALIAS tgraph_scotch)
target_link_libraries(tgraph_scotch INTERFACE ${SCOTCH_LIBRARY} ${SCOTCHERR_LIBRARY} Threads::Threads)

if(TGRAPH_PYTHON)
  # Debian python3-dev, pybind11-dev (python3-pybind11), python3-pytest: they belong to
  # Debian's interpreter, preferred over another python3 earlier on PATH (pyenv, venv).
  if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python3_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python3 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
  find_package(pybind11 2.10 REQUIRED CONFIG)
endif()
if(TGRAPH_BUILD_TESTS)
  find_package(GTest REQUIRED CONFIG)
  include(GoogleTest)
endif()
if(TGRAPH_BUILD_BENCH)
  find_package(benchmark REQUIRED CONFIG)
endif()
