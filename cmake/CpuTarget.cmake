# Resolves SDF_CPU_TARGET into one -march flag (SDF_CPU_MARCH_FLAG), refusing a target the
# compiler does not know, and the ISA extensions that target enables (SDF_CPU_ISA, for
# provenance: the manifests record what the numbers were computed with).
include(CheckCXXCompilerFlag)
if(SDF_CPU_TARGET STREQUAL "portable")
  set(_march "x86-64-v2")
elseif(SDF_CPU_TARGET STREQUAL "native")
  set(_march "native")
else()
  set(_march "${SDF_CPU_TARGET}")
endif()
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$" OR _march STREQUAL "native")
  set(SDF_CPU_MARCH_FLAG "-march=${_march}")
  string(MAKE_C_IDENTIFIER "SDF_CXX_ACCEPTS_${_march}" _var)
  check_cxx_compiler_flag("${SDF_CPU_MARCH_FLAG}" ${_var})
  if(NOT ${_var})
    message(FATAL_ERROR "SDF_CPU_TARGET=${SDF_CPU_TARGET}: the compiler does not accept ${SDF_CPU_MARCH_FLAG}; "
                        "use portable, native or an -march value it knows (e.g. x86-64-v3)")
  endif()
else()
  set(SDF_CPU_MARCH_FLAG "")  # not x86-64: the compiler's default target is the portable one
endif()
# The ISA extensions the target enables, from the compiler's own predefined macros.
execute_process(
  COMMAND ${CMAKE_CXX_COMPILER} ${SDF_CPU_MARCH_FLAG} -dM -E -x c++ /dev/null
  OUTPUT_VARIABLE _macros ERROR_QUIET)
set(SDF_CPU_ISA "")
foreach(_ext SSE4_2 AVX AVX2 FMA AVX512F AVX512VL AVX512BW)
  if(_macros MATCHES "#define __${_ext}__ 1")
    string(TOLOWER "${_ext}" _lower)
    list(APPEND SDF_CPU_ISA "${_lower}")
  endif()
endforeach()
string(REPLACE ";" " " SDF_CPU_ISA "${SDF_CPU_ISA}")
message(STATUS "sdf: CPU target ${SDF_CPU_TARGET} (${SDF_CPU_MARCH_FLAG}); ISA: ${SDF_CPU_ISA}")

# Run-time dispatch (cpu_reference/dispatch/cpu_kernels.h): a portable x86-64 build compiles
# the hot search loops once per level in SDF_CPU_KERNEL_LEVELS and runs the widest the CPU
# supports; a build for one target (native, x86-64-v3, ...) compiles them once, for it. So does
# a Debug build: unoptimised, the kernels are not inlined into the per-level entry points and
# their shared out-of-line copies would mix levels (scripts/check-isa-objects).
if(SDF_CPU_TARGET STREQUAL "portable" AND SDF_CPU_MARCH_FLAG AND NOT CMAKE_BUILD_TYPE STREQUAL "Debug")
  set(SDF_CPU_DISPATCH ON)
  set(SDF_CPU_KERNEL_LEVELS x86-64-v2 x86-64-v3 x86-64-v4)
  foreach(_level IN LISTS SDF_CPU_KERNEL_LEVELS)
    string(MAKE_C_IDENTIFIER "SDF_CXX_ACCEPTS_${_level}" _var)
    check_cxx_compiler_flag("-march=${_level}" ${_var})
    if(NOT ${_var})
      message(FATAL_ERROR "SDF_CPU_TARGET=portable compiles the CPU kernels for x86-64-v2, -v3 and -v4, but the "
                          "compiler does not accept -march=${_level} (GCC 11 or Clang 12 do); build for one "
                          "target instead, e.g. -DSDF_CPU_TARGET=x86-64-v2")
    endif()
  endforeach()
  message(STATUS "sdf: CPU kernels for ${SDF_CPU_KERNEL_LEVELS}, the widest the CPU supports chosen at run time")
else()
  set(SDF_CPU_DISPATCH OFF)
  if(SDF_CPU_MARCH_FLAG)
    set(SDF_CPU_KERNEL_LEVELS "${_march}")
  else()
    set(SDF_CPU_KERNEL_LEVELS "default")
  endif()
  message(STATUS "sdf: CPU kernels compiled once, for ${SDF_CPU_KERNEL_LEVELS} (no run-time dispatch)")
endif()
