# avs_glue_code(target...): code with no hot loop of its own (component adapters, the command
# line, the live-view server, reports, deployments, YAML readers, tests) is compiled at -O1 in
# Release builds: about a fifth less compiler time than -O3 for these template-heavy files
# (docs/build.md), while the cores, the runtime, the MCAP/bag libraries and every benchmark,
# where the time per frame or per message is spent and measured, keep CMake's Release -O3.
# AVS_GLUE_O1=OFF compiles everything at -O3.
option(AVS_GLUE_O1 "Compile glue code (adapters, CLI, view, reports, tests) at -O1 in Release" ON)
function(avs_glue_code)
  if(AVS_GLUE_O1)
    foreach(target ${ARGN})
      # After CMAKE_CXX_FLAGS_RELEASE on the command line, so this -O1 wins.
      target_compile_options(${target} PRIVATE $<$<CONFIG:Release>:-O1>)
    endforeach()
  endif()
endfunction()
