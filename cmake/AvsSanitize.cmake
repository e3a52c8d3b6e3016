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
  if(AVS_SANITIZE MATCHES "undefined")
    add_compile_options(-fno-sanitize-recover=undefined)
  endif()
  if(AVS_SANITIZE STREQUAL "thread")
    # GCC 12 warns (-Wtsan) that TSan does not model std::atomic_thread_fence, which Boost.Asio
    # uses (the `avs view` server); that is a warning about TSan's coverage, not about our code,
    # and must not fail an AVS_WERROR build.
    add_compile_options(-Wno-error=tsan)
  endif()
  add_link_options(-fsanitize=${AVS_SANITIZE})
  # The clang fuzz sub-build has its own sanitizers; not twice.
  set(AVS_FUZZ OFF CACHE BOOL "" FORCE)
  message(STATUS "avs: sanitizer build (${AVS_SANITIZE})")
endif()
