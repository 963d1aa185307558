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
