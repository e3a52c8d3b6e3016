# avs_idl_library(TARGET <name> FILES <a.idl> ...)
#
# Compiles OMG IDL with Cyclone DDS's idlc (C language binding) at build time and
# generates, at configure time, a type registry so tools can find any topic type by
# its DDS name (e.g. "sensor_msgs::msg::dds_::Image_"):
#   - avs/msg/type_support.hpp : TypeSupport<CType> specialisations and C++ aliases
#   - type_registry.cpp        : every struct's descriptor, and the IDL text itself
# Our IDL files follow one convention (module <pkg> { module msg { module dds_ { ... }}}, or
# module srv for the request/reply types of services, one kind per file),
# which is what makes the regex scan below sufficient.
find_program(AVS_IDLC idlc REQUIRED)

function(avs_idl_library)
  cmake_parse_arguments(ARG "" "TARGET" "FILES" ${ARGN})
  set(gen_dir ${CMAKE_CURRENT_BINARY_DIR}/idl_gen)
  file(MAKE_DIRECTORY ${gen_dir}/avs/msg)
  set(sources "")
  set(traits "")
  set(aliases "")
  set(entries "")
  set(idl_texts "")
  set(includes "")
  foreach(idl ${ARG_FILES})
    get_filename_component(abs ${idl} ABSOLUTE)
    get_filename_component(base ${idl} NAME_WE)
    add_custom_command(
      OUTPUT ${gen_dir}/${base}.c ${gen_dir}/${base}.h
      COMMAND ${AVS_IDLC} -f case-sensitive -x final -I ${CMAKE_CURRENT_SOURCE_DIR} -o ${gen_dir} ${abs}
      DEPENDS ${abs}
      COMMENT "idlc ${base}.idl"
      VERBATIM)
    list(APPEND sources ${gen_dir}/${base}.c)
    string(APPEND includes "#include \"${base}.h\"\n")
    file(READ ${abs} text)
    string(REGEX MATCH "module ([A-Za-z0-9_]+) *{ *module (msg|srv)" _ "${text}")
    set(pkg ${CMAKE_MATCH_1})
    set(kind ${CMAKE_MATCH_2})
    if(NOT pkg)
      message(FATAL_ERROR "${idl}: expected 'module <pkg> { module msg { module dds_ {' (or srv)")
    endif()
    string(REGEX MATCHALL "struct +[A-Za-z0-9_]+_ *{" structs "${text}")
    foreach(s ${structs})
      string(REGEX REPLACE "struct +([A-Za-z0-9_]+_) *{" "\\1" name "${s}")
      string(REGEX REPLACE "_$" "" short "${name}")
      set(ctype "${pkg}_${kind}_dds__${name}")
      string(APPEND traits "template <> struct TypeSupport<${ctype}> {\n  static const dds_topic_descriptor_t* descriptor() { return &${ctype}_desc; }\n  static constexpr const char* dds_name = \"${pkg}::${kind}::dds_::${name}\";\n};\n")
      string(APPEND aliases "namespace ${pkg} { using ${short} = ::${ctype}; }\n")
      string(APPEND entries "    {\"${pkg}::${kind}::dds_::${name}\", &${ctype}_desc, sizeof(${ctype})},\n")
    endforeach()
    # Raw string delimiter chosen so IDL comments cannot end it.
    string(APPEND idl_texts "    {\"${base}.idl\", R\"avsidl(${text})avsidl\"},\n")
  endforeach()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/type_support.hpp.in ${gen_dir}/avs/msg/type_support.hpp @ONLY)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/type_registry.cpp.in ${gen_dir}/type_registry.cpp @ONLY)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ARG_FILES})
  add_library(${ARG_TARGET} STATIC ${sources} ${gen_dir}/type_registry.cpp)
  target_include_directories(${ARG_TARGET} PUBLIC ${gen_dir} ${PROJECT_SOURCE_DIR}/runtime/include)
  target_link_libraries(${ARG_TARGET} PUBLIC CycloneDDS::ddsc)
  set_target_properties(${ARG_TARGET} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
