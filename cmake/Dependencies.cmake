# Finds every dependency in one place. All come from Debian packages listed in
# scripts/debian-packages.txt; nothing is downloaded at configure or build time.

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(tinyobjloader REQUIRED)
find_package(OpenSSL REQUIRED)            # SHA-256 of inputs for provenance
find_package(ZLIB REQUIRED)               # gzip-compressed mesh files
find_package(Threads REQUIRED)

# OpenImageIO writes PNG/EXR images; it is optional so that GPU machines without it can
# still build and run the samplers (images are then written as PFM/PPM).
find_package(OpenImageIO CONFIG QUIET)
set(SDF_HAVE_OIIO ${OpenImageIO_FOUND})
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
if(SDF_OPENVDB_INCLUDE AND SDF_OPENVDB_LIBRARY AND TBB_FOUND AND Imath_FOUND)
  set(SDF_HAVE_OPENVDB 1)
  add_library(sdf_openvdb INTERFACE)
  target_include_directories(sdf_openvdb SYSTEM INTERFACE ${SDF_OPENVDB_INCLUDE})
  target_link_libraries(sdf_openvdb INTERFACE ${SDF_OPENVDB_LIBRARY} TBB::tbb Imath::Imath)
endif()
message(STATUS "sdf: OpenVDB ${SDF_HAVE_OPENVDB} (.vdb export and the OpenVDB peer)")

# MPI (Open MPI from Debian) is optional: distributed runs (harness/distributed).
set(SDF_HAVE_MPI OFF)
if(NOT SDF_ENABLE_MPI STREQUAL "OFF")
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
      set(CMAKE_CUDA_ARCHITECTURES 90 CACHE STRING "CUDA architectures (90 = H100/H200)")
    endif()
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    set(SDF_HAVE_CUDA ON)
  elseif(SDF_ENABLE_CUDA STREQUAL "ON")
    message(FATAL_ERROR "SDF_ENABLE_CUDA=ON but no CUDA compiler (nvcc) was found")
  endif()
endif()
