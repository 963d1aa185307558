# Finds every dependency in one place. All come from Debian packages listed in
# scripts/debian-packages.txt; nothing is downloaded at configure or build time.

# A required package that is missing stops the configure step with the Debian package that has
# it and how to install it, instead of CMake's "X not found" (a stock Ubuntu + CUDA image has
# none of them; scripts/device/make-gpu-prefix carries them to the lent GPU machines).
function(sdf_require found what debian)
  if(NOT ${found})
    message(FATAL_ERROR "sdf: ${what} was not found. Install the Debian/Ubuntu package ${debian} "
                        "(scripts/install-deps installs every package of scripts/debian-packages.txt; "
                        "README.md, \"Quick start\"), or point CMAKE_PREFIX_PATH at a prefix that has it.")
  endif()
endfunction()

find_package(Eigen3 3.3 NO_MODULE QUIET)
sdf_require(Eigen3_FOUND "Eigen 3.3" libeigen3-dev)
find_package(nlohmann_json 3.10 QUIET)
sdf_require(nlohmann_json_FOUND "nlohmann_json 3.10" nlohmann-json3-dev)
if(SDF_WHEEL)
  # tinyobjloader: Debian ships no static archive, so the wheel compiles the header's
  # implementation (the double-precision variant the shared libtinyobjloader_double is).
  find_path(SDF_TINYOBJLOADER_INCLUDE tiny_obj_loader.h)
  sdf_require(SDF_TINYOBJLOADER_INCLUDE "tinyobjloader's header tiny_obj_loader.h" libtinyobjloader-dev)
  file(WRITE ${CMAKE_BINARY_DIR}/sdf_tinyobjloader.cpp "#define TINYOBJLOADER_IMPLEMENTATION\n#include <tiny_obj_loader.h>\n")
  add_library(sdf_tinyobjloader STATIC ${CMAKE_BINARY_DIR}/sdf_tinyobjloader.cpp)
  target_include_directories(sdf_tinyobjloader SYSTEM PUBLIC ${SDF_TINYOBJLOADER_INCLUDE})
  target_compile_definitions(sdf_tinyobjloader PUBLIC TINYOBJLOADER_USE_DOUBLE)
  set_target_properties(sdf_tinyobjloader PROPERTIES POSITION_INDEPENDENT_CODE ON)
  add_library(tinyobjloader::tinyobjloader_double ALIAS sdf_tinyobjloader)
  # Static archives where Debian ships them compiled position-independent: libcrypto.a. GMP's
  # libgmp.a is not wholly (assert.o) and libz.a not at all, so they cannot go into the module:
  # setup.py bundles libgmp.so.10 and libz.so.1.
  set(OPENSSL_USE_STATIC_LIBS TRUE)
  set(CMAKE_CUDA_RUNTIME_LIBRARY Static)
  # MPFR (no position-independent libmpfr.a) stays a shared library that CGAL lists but this
  # code never calls: --as-needed drops it (a call would fail the check of setup.py loudly).
  add_link_options(LINKER:--as-needed)
  # Without the run paths of the build machine's libraries: what is not static is bundled.
  set(CMAKE_INSTALL_RPATH_USE_LINK_PATH OFF)
else()
  find_package(tinyobjloader QUIET)
  sdf_require(tinyobjloader_FOUND "tinyobjloader" libtinyobjloader-dev)
endif()
find_package(OpenSSL QUIET)               # SHA-256 of inputs for provenance
sdf_require(OPENSSL_FOUND "OpenSSL's libcrypto" libssl-dev)
find_package(ZLIB QUIET)                  # gzip-compressed mesh files
sdf_require(ZLIB_FOUND "zlib" zlib1g-dev)
find_package(Threads REQUIRED)
# Exact predicates of the mesh report (core/mesh/exact_predicates.h): CGAL 5 is header-only;
# its kernel brings GMP and MPFR for the exact fallback.
find_package(CGAL 5 QUIET)
sdf_require(CGAL_FOUND "CGAL 5 (the mesh report's exact predicates; it brings GMP and MPFR)"
            "libcgal-dev (with libgmp-dev and libmpfr-dev)")
find_package(CLI11 QUIET)                 # the tools' command lines (apps/)
sdf_require(CLI11_FOUND "CLI11" libcli11-dev)
# OpenImageIO writes PNG/EXR images; it is optional so that GPU machines without it can
# still build and run the samplers (images are then written as PFM/PPM).
set(SDF_HAVE_OIIO 0)
if(NOT SDF_WHEEL)
  find_package(OpenImageIO CONFIG QUIET)
  set(SDF_HAVE_OIIO ${OpenImageIO_FOUND})
endif()
# Debian 12's OpenImageIO target lists /usr/include/opencv4 even without libopencv-dev, and
# CMake refuses a target with a missing include directory: keep only the existing ones.
if(SDF_HAVE_OIIO)
  foreach(_prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
    get_target_property(_dirs OpenImageIO::OpenImageIO ${_prop})
    if(_dirs)
      set(_existing "")
      foreach(_d IN LISTS _dirs)
        if(EXISTS "${_d}")
          list(APPEND _existing "${_d}")
        endif()
      endforeach()
      set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${_prop} "${_existing}")
    endif()
  endforeach()
endif()

# OpenVDB is optional: with it, fields can be exported as .vdb (harness/io/vdb_file.cpp) and
# the peers experiment compares with its mesh-to-volume. Debian's FindOpenVDB.cmake fails hard
# (not QUIET) without libboost-iostreams-dev, which the headers used here do not need: find
# the header and the library directly. OpenVDB's headers use Imath's half: Imath is linked
# after the objects that use it (with --as-needed an earlier Imath, pulled in by
# OpenImageIO, is dropped: "DSO missing").
set(SDF_HAVE_OPENVDB 0)
find_path(SDF_OPENVDB_INCLUDE openvdb/openvdb.h)
find_library(SDF_OPENVDB_LIBRARY openvdb)
find_package(TBB QUIET)
find_package(Imath CONFIG QUIET)
if(NOT SDF_WHEEL AND SDF_OPENVDB_INCLUDE AND SDF_OPENVDB_LIBRARY AND TBB_FOUND AND Imath_FOUND)
  set(SDF_HAVE_OPENVDB 1)
  add_library(sdf_openvdb INTERFACE)
  target_include_directories(sdf_openvdb SYSTEM INTERFACE ${SDF_OPENVDB_INCLUDE})
  target_link_libraries(sdf_openvdb INTERFACE ${SDF_OPENVDB_LIBRARY} TBB::tbb Imath::Imath)
endif()
message(STATUS "sdf: OpenVDB ${SDF_HAVE_OPENVDB} (.vdb export and the OpenVDB peer)")

# NanoVDB is optional and header-only: with it, a sparse band is also written as .nvdb
# (harness/io/sparse_nvdb_file.cpp) and, with CUDA, the peers experiment times its GPU
# MeshToGrid. Not a Debian package (Debian's OpenVDB 10 ships no NanoVDB headers): the folder
# holding nanovdb/NanoVDB.h comes from SDF_NANOVDB_DIR (cache variable; default: the
# environment's SDF_NANOVDB_DIR, else nanovdb/ of $SDF_PEERS_DIR, data/peers or ../shared/peers,
# else an installed OpenVDB 12 or later's include folder). The layout with tools/GridBuilder.h,
# tools/CreateNanoGrid.h and io/IO.h (NanoVDB 32.7, OpenVDB 12, and later) is required.
set(SDF_HAVE_NANOVDB 0)
set(_sdf_nanovdb_default "")
foreach(_dir "$ENV{SDF_NANOVDB_DIR}" "$ENV{SDF_PEERS_DIR}/nanovdb" "${CMAKE_SOURCE_DIR}/data/peers/nanovdb"
             "${CMAKE_SOURCE_DIR}/../shared/peers/nanovdb")
  if(NOT _sdf_nanovdb_default AND NOT _dir STREQUAL "/nanovdb" AND _dir AND EXISTS "${_dir}/nanovdb/NanoVDB.h")
    get_filename_component(_sdf_nanovdb_default "${_dir}" ABSOLUTE)
  endif()
endforeach()
if(NOT _sdf_nanovdb_default)
  find_path(_sdf_nanovdb_installed nanovdb/tools/CreateNanoGrid.h)
  if(_sdf_nanovdb_installed)
    set(_sdf_nanovdb_default "${_sdf_nanovdb_installed}")
  endif()
endif()
set(SDF_NANOVDB_DIR "${_sdf_nanovdb_default}" CACHE PATH
    "Folder holding nanovdb/NanoVDB.h (default: $SDF_NANOVDB_DIR, nanovdb/ of the peers' snapshots, or an installed OpenVDB 12+)")
set(SDF_NANOVDB_WHY_NOT "no nanovdb/NanoVDB.h in SDF_NANOVDB_DIR ('${SDF_NANOVDB_DIR}')")
if(NOT SDF_WHEEL AND SDF_NANOVDB_DIR AND EXISTS "${SDF_NANOVDB_DIR}/nanovdb/NanoVDB.h")
  if(EXISTS "${SDF_NANOVDB_DIR}/nanovdb/tools/GridBuilder.h" AND EXISTS "${SDF_NANOVDB_DIR}/nanovdb/tools/CreateNanoGrid.h"
     AND EXISTS "${SDF_NANOVDB_DIR}/nanovdb/io/IO.h")
    set(SDF_HAVE_NANOVDB 1)
    set(SDF_NANOVDB_WHY_NOT "")
    add_library(sdf_nanovdb INTERFACE)
    target_include_directories(sdf_nanovdb SYSTEM INTERFACE ${SDF_NANOVDB_DIR})
    target_link_libraries(sdf_nanovdb INTERFACE Threads::Threads)
  else()
    set(SDF_NANOVDB_WHY_NOT "${SDF_NANOVDB_DIR} has nanovdb/NanoVDB.h but not tools/GridBuilder.h, tools/CreateNanoGrid.h "
                            "and io/IO.h (NanoVDB 32.7 / OpenVDB 12 or later)")
  endif()
endif()
if(SDF_HAVE_NANOVDB)
  message(STATUS "sdf: NanoVDB 1 (.nvdb export; the NanoVDB MeshToGrid peer with CUDA; test sparse_nvdb_test) "
                 "headers in ${SDF_NANOVDB_DIR}")
else()
  message(STATUS "sdf: NanoVDB 0 (no .nvdb export, no NanoVDB peer, test sparse_nvdb_test not built): ${SDF_NANOVDB_WHY_NOT}")
endif()

# MPI (Open MPI from Debian) is optional: distributed runs (harness/distributed).
set(SDF_HAVE_MPI OFF)
if(NOT SDF_ENABLE_MPI STREQUAL "OFF" AND NOT SDF_WHEEL)
  find_package(MPI COMPONENTS CXX QUIET)
  if(MPI_CXX_FOUND)
    set(SDF_HAVE_MPI ON)
  elseif(SDF_ENABLE_MPI STREQUAL "ON")
    message(FATAL_ERROR "SDF_ENABLE_MPI=ON but no MPI (C++) was found; install libopenmpi-dev and openmpi-bin")
  endif()
endif()

if(SDF_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(SDF_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# CUDA: enabled automatically when nvcc is found (SDF_ENABLE_CUDA=AUTO), switchable off.
set(SDF_HAVE_CUDA OFF)
if(NOT SDF_ENABLE_CUDA STREQUAL "OFF")
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      # Every current NVIDIA GPU: machine code for Turing (75: T4, RTX 20xx), Ampere (80: A100;
      # 86: A10, RTX 30xx), Ada (89: L4, L40, RTX 40xx) and Hopper (90: H100, H200), and PTX of
      # 90 that the driver compiles for newer GPUs (Blackwell) on first use. Warp reductions
      # take redux.sync from sm_80 on and shuffles before (cuda/util/warp_reduce.cuh), with
      # the same bits; nothing else is architecture-specific. One architecture builds
      # faster: -DCMAKE_CUDA_ARCHITECTURES=90 (or native).
      set(CMAKE_CUDA_ARCHITECTURES "75-real;80-real;86-real;89-real;90-real;90-virtual"
          CACHE STRING "CUDA architectures: machine code for sm_75 to sm_90, PTX for newer GPUs")
    endif()
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    # Several architectures: nvcc compiles them one after another unless told to use threads,
    # so the default list would cost its length in wall time on every machine with cores to spare.
    list(LENGTH CMAKE_CUDA_ARCHITECTURES _sdf_cuda_arch_count)
    if(_sdf_cuda_arch_count GREATER 1)
      add_compile_options("$<$<COMPILE_LANGUAGE:CUDA>:SHELL:--threads 0>")
    endif()
    set(SDF_HAVE_CUDA ON)
  elseif(SDF_ENABLE_CUDA STREQUAL "ON")
    message(FATAL_ERROR "SDF_ENABLE_CUDA=ON but no CUDA compiler (nvcc) was found")
  endif()
endif()

# The Python module sdf_lattices (python/): pybind11 and a Python with its headers and NumPy
# (Debian: pybind11-dev, python3-pybind11, python3-dev, python3-numpy). Optional: without
# them the module is skipped, like the CUDA backend. The interpreter is the first python3 that
# imports numpy and has its headers: a python3 first on PATH (pyenv, a virtual environment)
# may lack them, and the module must be built for the interpreter that will import it
# (-DPython3_EXECUTABLE=... chooses another).
set(SDF_BUILD_PYTHON "AUTO" CACHE STRING "Build the Python module: AUTO (when pybind11 and Python are found), ON or OFF")
set_property(CACHE SDF_BUILD_PYTHON PROPERTY STRINGS AUTO ON OFF)
set(SDF_HAVE_PYTHON_MODULE OFF)
if(NOT SDF_BUILD_PYTHON STREQUAL "OFF")
  if(NOT Python3_EXECUTABLE)
    find_program(_sdf_path_python3 NAMES python3)
    foreach(candidate IN ITEMS ${_sdf_path_python3} /usr/bin/python3)
      execute_process(COMMAND ${candidate} -c
                        "import numpy, sysconfig, os, sys; sys.exit(0 if os.path.exists(os.path.join(sysconfig.get_paths()['include'], 'Python.h')) else 1)"
                      RESULT_VARIABLE _sdf_python_ok OUTPUT_QUIET ERROR_QUIET)
      if(_sdf_python_ok EQUAL 0)
        set(Python3_EXECUTABLE ${candidate} CACHE FILEPATH "The python3 the module is built for")
        break()
      endif()
    endforeach()
  endif()
  find_package(Python3 COMPONENTS Interpreter Development.Module NumPy QUIET)
  if(Python3_FOUND)
    find_package(pybind11 CONFIG QUIET)
  endif()
  if(Python3_FOUND AND pybind11_FOUND)
    set(SDF_HAVE_PYTHON_MODULE ON)
  elseif(SDF_BUILD_PYTHON STREQUAL "ON")
    message(FATAL_ERROR "SDF_BUILD_PYTHON=ON but pybind11 or a python3 with headers and NumPy was not found "
                        "(Debian: pybind11-dev python3-pybind11 python3-dev python3-numpy)")
  endif()
endif()
