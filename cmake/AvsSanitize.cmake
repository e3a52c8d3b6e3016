# Sanitizer builds of the whole tree (issue 20 section 4): -DAVS_SANITIZE=address,undefined
# (ASan + UBSan, `bash tools/run.sh test --sanitize`) or -DAVS_SANITIZE=thread (TSan). Every
# target, tests included, is instrumented; findings stop the test that hit them (UBSan does not
# recover). Known findings in code that is not ours are suppressed, each with its reason, in
# tests/sanitizers/ (tools/run.sh points the runtime at those files).
set(AVS_SANITIZE "" CACHE STRING "Sanitizers for the whole build: address,undefined | thread | empty")
if(AVS_SANITIZE)
  if(NOT AVS_SANITIZE MATCHES "^(address,undefined|address|undefined|thread)$")
    message(FATAL_ERROR "AVS_SANITIZE='${AVS_SANITIZE}': use address,undefined, address, undefined or thread")
  endif()
  add_compile_options(-fsanitize=${AVS_SANITIZE} -fno-omit-frame-pointer -g1)
  # A Release sanitizer build is compiled at -O1, as ASan's documentation advises for a usable
  # speed: -O3 adds compile time (CI builds the plain tree and this one) and the checks are the same.
  # The speed figures come from the plain build, never from this one.
  set(CMAKE_C_FLAGS_RELEASE "-O1 -DNDEBUG")
  set(CMAKE_CXX_FLAGS_RELEASE "-O1 -DNDEBUG")
  if(AVS_SANITIZE MATCHES "undefined")
    add_compile_options(-fno-sanitize-recover=undefined)
  endif()
  if(AVS_SANITIZE STREQUAL "thread")
    # GCC 12 warns (-Wtsan) that TSan does not model std::atomic_thread_fence, which Boost.Asio
    # uses (the `avs view` server) and so do our sample pools (SamplePool, LentSamplePool: the
    # acquire fence after seeing use_count() == 1). A warning about TSan's coverage: TSan may
    # miss (or wrongly report) an ordering that rests on those fences. It must not fail an
    # AVS_WERROR build.
    add_compile_options(-Wno-error=tsan)
  endif()
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # Instrumented code changes GCC's flow analysis: with ASan + UBSan, GCC 12 reports
    # std::function members inside libstdc++'s std::regex as maybe-uninitialized
    # (mcap_malformed_test, seen 2026-12-04). The uninstrumented build keeps that warning as an
    # error, so nothing is lost by not asking it of the instrumented one.
    add_compile_options(-Wno-maybe-uninitialized)
  endif()
  add_link_options(-fsanitize=${AVS_SANITIZE})
  # The clang fuzz sub-build has its own sanitizers; not twice.
  set(AVS_FUZZ OFF CACHE BOOL "" FORCE)
  message(STATUS "avs: sanitizer build (${AVS_SANITIZE})")
endif()
