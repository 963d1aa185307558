# Project-wide warnings for host code.
add_library(sdf_warnings INTERFACE)
target_compile_options(sdf_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wno-missing-field-initializers>)
