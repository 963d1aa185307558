# Run at build time (harness/CMakeLists.txt, target sdf_version_header), not at configure
# time, so that `--version` names the commit the tools were built from even after later
# commits without a reconfigure. Writes OUTPUT only when its text changes (file(CONFIGURE)),
# so an unchanged commit rebuilds nothing.
#   -DSOURCE_DIR=... -DOUTPUT=... -DVERSION=0.1.0 -DCOMMIT_GIVEN=<SDF_SOURCE_COMMIT, may be empty>
# Without git or a .git directory (a tarball on a GPU machine) the commit is COMMIT_GIVEN,
# passed in by whoever copied the tree (-DSDF_SOURCE_COMMIT=<sha>[-dirty]), else "unknown".
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse HEAD
                OUTPUT_VARIABLE SDF_BUILD_COMMIT RESULT_VARIABLE _rc
                OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(_rc EQUAL 0 AND NOT SDF_BUILD_COMMIT STREQUAL "")
  execute_process(COMMAND git -C "${SOURCE_DIR}" status --porcelain --untracked-files=no
                  OUTPUT_VARIABLE _status RESULT_VARIABLE _rc ERROR_QUIET)
  if(_rc EQUAL 0 AND _status STREQUAL "")
    set(SDF_BUILD_DIRTY 0)
  else()
    set(SDF_BUILD_DIRTY 1)
  endif()
elseif(COMMIT_GIVEN MATCHES "^(.+)-dirty$")
  set(SDF_BUILD_COMMIT "${CMAKE_MATCH_1}")
  set(SDF_BUILD_DIRTY 1)
elseif(NOT COMMIT_GIVEN STREQUAL "")
  set(SDF_BUILD_COMMIT "${COMMIT_GIVEN}")
  set(SDF_BUILD_DIRTY 0)
else()
  set(SDF_BUILD_COMMIT "unknown")
  set(SDF_BUILD_DIRTY 1)
endif()
file(CONFIGURE OUTPUT "${OUTPUT}" CONTENT [[
// Generated at build time by cmake/WriteVersionHeader.cmake: the version and the commit the
// tools and the Python module were built from (harness/provenance/version.h).
#pragma once
#define SDF_VERSION "@VERSION@"
#define SDF_BUILD_COMMIT "@SDF_BUILD_COMMIT@"
#define SDF_BUILD_DIRTY @SDF_BUILD_DIRTY@
]] @ONLY)
