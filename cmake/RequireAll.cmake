# SPDX-License-Identifier: MIT
# TGRAPH_REQUIRE_ALL: the optional dependencies become required. Without it, a build that
# does not find SimGrid, StarPU, OpenMPI, PT-Scotch or Chromium leaves out what needs them
# (and their tests) with a status line; with it (CI: .ci/run), configuring fails naming each
# one missing, so a broken lookup cannot silently drop tests. Included after the modules and
# tests are added: it reads what they found from their targets.

# _tgraph_require(TARGET PROPERTY DEFINITION WHAT): appends WHAT to _tgraph_missing unless
# TARGET's PROPERTY (a list of compile definitions) holds DEFINITION.
function(_tgraph_require target property definition what)
  if(TARGET ${target})
    get_target_property(_defs ${target} ${property})
    if(_defs AND "${definition}" IN_LIST _defs)
      return()
    endif()
  endif()
  set(_tgraph_missing ${_tgraph_missing} "${what}" PARENT_SCOPE)
endfunction()

if(TGRAPH_REQUIRE_ALL)
  set(_tgraph_missing "")
  _tgraph_require(tgraph_model INTERFACE_COMPILE_DEFINITIONS TGRAPH_HAVE_SIMGRID=1
                  "SimGrid (pkg-config simgrid, Debian libsimgrid-dev)")
  _tgraph_require(tgraph_replay INTERFACE_COMPILE_DEFINITIONS TGRAPH_HAVE_STARPU=1
                  "StarPU (pkg-config starpu-1.3, Debian libstarpu-dev)")
  if(NOT TARGET tgraph_mpi)
    list(APPEND _tgraph_missing "OpenMPI (find_package(MPI COMPONENTS CXX), Debian libopenmpi-dev)")
  elseif(NOT CMAKE_CXX_COMPILER MATCHES "smpicxx")
    # An SMPI build (SimGrid's smpicxx) leaves out both on purpose (mpi/CMakeLists.txt).
    _tgraph_require(tgraph_mpi COMPILE_DEFINITIONS TGRAPH_HAVE_STARPU_MPI=1
                    "StarPU-MPI (pkg-config starpumpi-1.3, Debian libstarpu-dev)")
    _tgraph_require(tgraph_mpi INTERFACE_COMPILE_DEFINITIONS TGRAPH_HAVE_PTSCOTCH=1
                    "PT-Scotch (scotch/ptscotch.h, libptscotch, libptscotcherr, Debian libptscotch-dev)")
  endif()
  # tgraph::ode (ode/CMakeLists.txt), when the samples and the measure module are built.
  if(TARGET tgraph_measure AND NOT TARGET tgraph_ode)
    list(APPEND _tgraph_missing "ODE (pkg-config ode, Debian libode-dev)")
  endif()
  # The browser test of the HTML report (tests/viz) is the only user of Chromium.
  if(TGRAPH_BUILD_TESTS AND NOT TGRAPH_CHROMIUM)
    list(APPEND _tgraph_missing "Chromium (chromium or chromium-browser on PATH, Debian chromium)")
  endif()
  if(_tgraph_missing)
    list(JOIN _tgraph_missing "\n  " _tgraph_missing_lines)
    message(FATAL_ERROR "tgraph: TGRAPH_REQUIRE_ALL is on and these were not found:\n  "
                        "${_tgraph_missing_lines}\n"
                        "Install them (scripts/setup.sh lists the Debian packages), or configure "
                        "with -DTGRAPH_REQUIRE_ALL=OFF to build without them.")
  endif()
  message(STATUS "tgraph: TGRAPH_REQUIRE_ALL: SimGrid, StarPU, StarPU-MPI, OpenMPI, PT-Scotch "
                 "and Chromium found")
endif()
