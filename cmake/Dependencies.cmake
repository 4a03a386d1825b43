# SPDX-License-Identifier: MIT
# Every dependency comes from a Debian package; none is vendored.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)
find_package(Eigen3 3.4 REQUIRED CONFIG)
find_package(nlohmann_json 3.10 REQUIRED CONFIG)
find_package(CLI11 REQUIRED CONFIG)
find_package(TBB REQUIRED CONFIG)
find_package(OpenMP REQUIRED COMPONENTS CXX)
pkg_check_modules(HWLOC REQUIRED IMPORTED_TARGET hwloc)
pkg_check_modules(GRAPHVIZ REQUIRED IMPORTED_TARGET libcgraph libgvc)

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
