# libFuzzer targets (issue 20 section 3), one per parser of outside input, in tests/fuzz.
#
# The project compiler may be g++, which has no libFuzzer, so the targets are built by a second
# CMake build of this source tree with clang (the "fuzz sub-build", ${CMAKE_BINARY_DIR}/fuzz):
# everything the targets link is compiled there with -fsanitize=fuzzer-no-link,address,undefined,
# so libFuzzer sees the coverage of our parsers and not only of the harness. The main build
# drives it (ExternalProject, only the targets and what they link are built) and registers
# one CTest test per target, label `fuzz`, that runs it on its committed corpus for
# AVS_FUZZ_TEST_SECONDS. `tools/fuzz.sh [SECONDS]` runs the longer campaign.
#
#   avs_add_fuzz_target(<parser> SOURCES <files...> LIBS <targets...> [CORPUS <more dirs...>])
#
# adds, in the sub-build, the executable fuzz_<parser>, and in the main build the test
# fuzz_<parser> on the seeds in corpus/<parser>/ next to the calling CMakeLists.txt (and the
# CORPUS folders). The
# limits of a run (one place: AvsFuzz.cmake, read by tools/fuzz.sh from avs_fuzz_options.txt):
# an input taking longer than 1 s is a hang, more than 2 GB resident memory an out-of-memory.
option(AVS_FUZZ "Build the libFuzzer targets with clang (tests/fuzz) and run each as a test" ON)
option(AVS_FUZZ_BUILD "Internal: this build is the clang fuzz sub-build" OFF)
set(AVS_FUZZ_TEST_SECONDS 20 CACHE STRING "Seconds each fuzz target runs as a CTest test")
set(AVS_FUZZ_RUN_OPTIONS -timeout=1 -rss_limit_mb=2048 -print_final_stats=1)
set(AVS_FUZZ_SANITIZE -fsanitize=address,undefined -fno-sanitize-recover=undefined
    -fno-omit-frame-pointer)

if(AVS_FUZZ AND NOT AVS_FUZZ_BUILD AND AVS_BUILD_TESTS)
  find_program(AVS_CLANG clang-14 NAMES clang)
  find_program(AVS_CLANGXX clang++-14 NAMES clang++)
  if(AVS_CLANG AND AVS_CLANGXX)
    set(AVS_FUZZ_BINARY_DIR ${CMAKE_BINARY_DIR}/fuzz)
    include(ExternalProject)
    # $(MAKE) shares the parent's job slots (make -jN); other generators run their own.
    if(CMAKE_GENERATOR MATCHES "Make")
      set(build_command $(MAKE) avs_fuzz_targets)
    else()
      set(build_command ${CMAKE_COMMAND} --build . --target avs_fuzz_targets)
    endif()
    # Only what the fuzz targets need: the libraries they link and no tests, tools or
    # benchmarks. CMAKE_BUILD_TYPE RelWithDebInfo: optimised, with line numbers in reports.
    ExternalProject_Add(avs_fuzz_build
      SOURCE_DIR ${PROJECT_SOURCE_DIR}
      BINARY_DIR ${AVS_FUZZ_BINARY_DIR}
      CMAKE_ARGS -DCMAKE_C_COMPILER=${AVS_CLANG} -DCMAKE_CXX_COMPILER=${AVS_CLANGXX}
                 -DCMAKE_BUILD_TYPE=RelWithDebInfo
                 -DCMAKE_C_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER}
                 -DCMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER}
                 -DAVS_FUZZ_BUILD=ON -DAVS_BUILD_TESTS=OFF -DAVS_BUILD_BENCHMARKS=OFF
                 # clang's warnings differ from g++'s; the main build's -Werror guards the code.
                 -DAVS_WERROR=OFF
                 -DAVS_ONLY_SUBDIRS=camera|decode|geometry|projector|servo|sim
      LIST_SEPARATOR |
      BUILD_COMMAND ${build_command}
      INSTALL_COMMAND ""
      BUILD_ALWAYS ON
      USES_TERMINAL_BUILD ON)
    file(WRITE ${CMAKE_BINARY_DIR}/avs_fuzz_options.txt
         "${AVS_FUZZ_BINARY_DIR}/tests/fuzz\n${AVS_FUZZ_RUN_OPTIONS}\n")
  else()
    message(STATUS "clang/clang++ not found: the libFuzzer targets (tests/fuzz) are not built "
                   "(apt install clang libclang-rt-14-dev)")
    set(AVS_FUZZ OFF)
  endif()
endif()

if(AVS_FUZZ_BUILD)
  # Coverage and sanitizer instrumentation for every file of the sub-build; the fuzz targets'
  # link adds libFuzzer itself (-fsanitize=fuzzer).
  add_compile_options(-fsanitize=fuzzer-no-link ${AVS_FUZZ_SANITIZE})
  add_link_options(${AVS_FUZZ_SANITIZE})
  add_custom_target(avs_fuzz_targets)
endif()

function(avs_add_fuzz_target parser)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;CORPUS" ${ARGN})
  set(name fuzz_${parser})
  if(AVS_FUZZ_BUILD)
    add_executable(${name} ${ARG_SOURCES})
    target_link_libraries(${name} PRIVATE ${ARG_LIBS})
    target_link_options(${name} PRIVATE -fsanitize=fuzzer)
    avs_apply_warnings(${name})
    add_dependencies(avs_fuzz_targets ${name})
  elseif(AVS_FUZZ AND TARGET avs_fuzz_build)
    # New inputs go to a scratch folder (first corpus argument), never into the repository.
    set(work ${CMAKE_CURRENT_BINARY_DIR}/${name})
    add_test(NAME ${name}
      COMMAND bash -c "rm -rf \"$0\" && mkdir -p \"$0/new\" && cd \"$0\" && exec \"$@\""
              ${work} ${AVS_FUZZ_BINARY_DIR}/tests/fuzz/${name}
              -max_total_time=${AVS_FUZZ_TEST_SECONDS} -seed=1 ${AVS_FUZZ_RUN_OPTIONS}
              new ${CMAKE_CURRENT_SOURCE_DIR}/corpus/${parser} ${ARG_CORPUS})
    math(EXPR timeout "${AVS_FUZZ_TEST_SECONDS} * 3 + 60")
    set_tests_properties(${name} PROPERTIES LABELS fuzz TIMEOUT ${timeout})
  endif()
endfunction()
