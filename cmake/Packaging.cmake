# Installation and the pip package (setup.py, pyproject.toml; README.md, "Python").
#
# `cmake --install build --prefix P` puts the tools into P/bin and, when the Python module is
# built, the package into P/SDF_PYTHON_INSTALL_DIR/sdf_lattices/ (python/CMakeLists.txt)
# with build_info.json: what this build found of the optional parts, returned by
# sdf_lattices.build_info(). The target sdf_package builds everything those rules install;
# setup.py builds it, installs it into a staging folder and packs the wheel from there.

# The tools: every executable apps/ defines (one list: apps/CMakeLists.txt).
get_property(_sdf_app_targets DIRECTORY ${PROJECT_SOURCE_DIR}/apps PROPERTY BUILDSYSTEM_TARGETS)
set(SDF_TOOLS "")
foreach(_target IN LISTS _sdf_app_targets)
  get_target_property(_type ${_target} TYPE)
  if(_type STREQUAL "EXECUTABLE")
    list(APPEND SDF_TOOLS ${_target})
  endif()
endforeach()
# Installed binaries keep the link directories outside the system's (a CUDA or MPI under
# /usr/local, say) in their run path, so that they start wherever they are installed.
if(SDF_WHEEL)
  # The portable wheel: the libraries setup.py bundles lie in site-packages/sdf_lattices.libs;
  # the tools are installed into the environment's bin/, beside lib/pythonX.Y/site-packages.
  set(SDF_WHEEL_LIBS_FROM_BIN "\$ORIGIN/../lib/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/site-packages/sdf_lattices.libs")
  set_target_properties(${SDF_TOOLS} PROPERTIES INSTALL_RPATH "${SDF_WHEEL_LIBS_FROM_BIN}")
else()
  set_target_properties(${SDF_TOOLS} PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
endif()
install(TARGETS ${SDF_TOOLS} RUNTIME DESTINATION bin)

add_custom_target(sdf_package)
add_dependencies(sdf_package ${SDF_TOOLS})

# ---- build_info.json ----------------------------------------------------------------------
# Each optional part: found or not, and what it is, or why it is missing and what adds it.
function(_sdf_json_string out value)
  string(REPLACE "\\" "\\\\" value "${value}")
  string(REPLACE "\"" "\\\"" value "${value}")
  string(REPLACE "\n" " " value "${value}")
  set(${out} "\"${value}\"" PARENT_SCOPE)
endfunction()

set(_sdf_parts "{}")
macro(_sdf_part name found detail)
  if(${found})
    set(_found true)
  else()
    set(_found false)
  endif()
  _sdf_json_string(_detail "${detail}")
  string(JSON _sdf_parts SET "${_sdf_parts}" "${name}" "{\"found\": ${_found}, \"detail\": ${_detail}}")
endmacro()

if(SDF_HAVE_CUDA)
  _sdf_part(cuda ON "CUDA ${CMAKE_CUDA_COMPILER_VERSION} (${CMAKE_CUDA_COMPILER}), architectures ${CMAKE_CUDA_ARCHITECTURES}; a GPU is used when present")
  # The architectures as a list ("90-real": machine code for sm_90, "90-virtual": PTX that
  # newer GPUs compile when they load it), so that a caller can check its GPU against it.
  set(_sdf_archs "[]")
  set(_sdf_i 0)
  foreach(_sdf_arch IN LISTS CMAKE_CUDA_ARCHITECTURES)
    string(JSON _sdf_archs SET "${_sdf_archs}" ${_sdf_i} "\"${_sdf_arch}\"")
    math(EXPR _sdf_i "${_sdf_i} + 1")
  endforeach()
  string(JSON _sdf_parts SET "${_sdf_parts}" cuda architectures "${_sdf_archs}")
elseif(SDF_ENABLE_CUDA STREQUAL "OFF")
  _sdf_part(cuda OFF "turned off (SDF_ENABLE_CUDA=OFF): CPU backend only")
else()
  _sdf_part(cuda OFF "no CUDA compiler (nvcc) found: CPU backend only")
endif()

if(SDF_HAVE_MPI)
  list(GET MPI_CXX_LIBRARIES -1 _mpi_library)
  _sdf_part(mpi ON "MPI ${MPI_CXX_VERSION} (${_mpi_library}, ${MPIEXEC_EXECUTABLE}): mpirun -np N runs one lattice over N ranks")
elseif(SDF_WHEEL)
  _sdf_part(mpi OFF "not built: left out of the portable wheel (SDF_WHEEL=ON); build from source with libopenmpi-dev for distributed runs")
elseif(SDF_ENABLE_MPI STREQUAL "OFF")
  _sdf_part(mpi OFF "turned off (SDF_ENABLE_MPI=OFF): single-process runs")
else()
  _sdf_part(mpi OFF "no MPI (C++) found (Debian libopenmpi-dev openmpi-bin): single-process runs")
endif()

if(SDF_HAVE_OPENVDB)
  _sdf_part(openvdb ON "${SDF_OPENVDB_LIBRARY}: .vdb export and the OpenVDB peer")
elseif(SDF_WHEEL)
  _sdf_part(openvdb OFF "not built: left out of the portable wheel (SDF_WHEEL=ON); build from source with libopenvdb-dev libtbb-dev for .vdb export")
else()
  set(_missing "")
  foreach(_piece IN ITEMS SDF_OPENVDB_INCLUDE SDF_OPENVDB_LIBRARY TBB_FOUND Imath_FOUND)
    if(NOT ${_piece})
      list(APPEND _missing ${_piece})
    endif()
  endforeach()
  string(REPLACE ";" ", " _missing "${_missing}")
  _sdf_part(openvdb OFF "not found (${_missing}; Debian libopenvdb-dev libtbb-dev): no .vdb export")
endif()

if(SDF_HAVE_OIIO)
  _sdf_part(openimageio ON "OpenImageIO ${OpenImageIO_VERSION}: PNG and EXR images")
elseif(SDF_WHEEL)
  _sdf_part(openimageio OFF "not built: left out of the portable wheel (SDF_WHEEL=ON): images are written as PPM and PFM")
else()
  _sdf_part(openimageio OFF "not found (Debian libopenimageio-dev): images are written as PPM and PFM")
endif()

set(_sdf_info "{}")
foreach(_pair IN ITEMS "version;${PROJECT_VERSION}" "build_type;${CMAKE_BUILD_TYPE}"
                       "cpu_target;${SDF_CPU_TARGET} (${SDF_CPU_MARCH_FLAG})"
                       "compiler;${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER_VERSION}"
                       "python;${Python3_VERSION} (${Python3_EXECUTABLE})")
  list(GET _pair 0 _key)
  list(GET _pair 1 _value)
  _sdf_json_string(_value "${_value}")
  string(JSON _sdf_info SET "${_sdf_info}" "${_key}" "${_value}")
endforeach()
if(SDF_WHEEL)
  string(JSON _sdf_info SET "${_sdf_info}" portable_wheel true)
else()
  string(JSON _sdf_info SET "${_sdf_info}" portable_wheel false)
endif()
string(JSON _sdf_info SET "${_sdf_info}" optional "${_sdf_parts}")

if(SDF_HAVE_PYTHON_MODULE)
  add_dependencies(sdf_package sdf_lattices)
  # Beside the package's other files in the build tree (PYTHONPATH=build/python) and installed
  # with them; rewritten only when it changes.
  file(CONFIGURE OUTPUT ${PROJECT_BINARY_DIR}/python/sdf_lattices/build_info.json CONTENT "${_sdf_info}\n" @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/python/sdf_lattices/build_info.json
          DESTINATION ${SDF_PYTHON_INSTALL_DIR}/sdf_lattices)
  if(SDF_WHEEL)
    set_target_properties(sdf_lattices PROPERTIES INSTALL_RPATH "\$ORIGIN/../sdf_lattices.libs")
  else()
    set_target_properties(sdf_lattices PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
  endif()
endif()
