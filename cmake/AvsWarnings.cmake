# avs_apply_warnings(target): one place for the project's warning flags.
# AVS_WERROR (ON in CI) turns warnings into errors.
option(AVS_WERROR "Treat compiler warnings as errors" OFF)
function(avs_apply_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-missing-field-initializers
    # GCC 12 reports false -Wrestrict positives inside std::string (GCC bug 105329); clang
    # (the fuzz build) has no such option.
    $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
    # ... and false -Wstringop-overread positives for std::string::find once it is inlined
    # into a larger unity batch (bench::option_words in the runtime's batch).
    $<$<CXX_COMPILER_ID:GNU>:-Wno-stringop-overread>)
  # A unity build includes .cpp files into one another: GCC then reports types of a file's
  # anonymous namespace used by its own classes as if they came from a header.
  if(CMAKE_UNITY_BUILD)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  endif()
  if(AVS_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
