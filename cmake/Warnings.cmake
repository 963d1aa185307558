# Project-wide warnings, host and CUDA (nvcc's own and the host compiler's through
# -Xcompiler). SDF_WARNINGS_AS_ERRORS turns them into errors: developers build with it on
# (scripts/build --dev), CI's and users' builds keep it off so a new compiler's new warning
# cannot break their build.
add_library(sdf_warnings INTERFACE)
target_compile_options(sdf_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wno-missing-field-initializers>
  $<$<COMPILE_LANGUAGE:CUDA>:-Xcompiler=-Wall,-Wextra,-Wno-missing-field-initializers --Wreorder
                             --Wext-lambda-captures-this -Wno-deprecated-gpu-targets>)
if(SDF_WARNINGS_AS_ERRORS)
  target_compile_options(sdf_warnings INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-Werror>
    $<$<COMPILE_LANGUAGE:CUDA>:-Werror=all-warnings -Xcompiler=-Werror>)
endif()
