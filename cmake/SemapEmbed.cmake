# semap_embed_files(TARGET tgt FUNCTION ns::name BASE_DIR dir FILES f...): compiles the files
# into `tgt` at build time, so an installed program needs no data path. The generated source
# defines
#   std::vector<std::pair<std::string_view, std::string_view>> ns::name();
# (path relative to BASE_DIR, contents); the target declares it where it uses it.
set(SEMAP_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/semap_embed_script.cmake)

function(semap_embed_files)
  cmake_parse_arguments(ARG "" "TARGET;FUNCTION;BASE_DIR" "FILES" ${ARGN})
  string(MAKE_C_IDENTIFIER "${ARG_FUNCTION}" stem)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded_${stem}.cpp)
  string(REPLACE ";" "|" files_arg "${ARG_FILES}")
  add_custom_command(OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DFUNCTION=${ARG_FUNCTION} -DBASE_DIR=${ARG_BASE_DIR}
            "-DFILES=${files_arg}" -P ${SEMAP_EMBED_SCRIPT}
    DEPENDS ${ARG_FILES} ${SEMAP_EMBED_SCRIPT}
    COMMENT "Embedding ${ARG_FUNCTION}"
    VERBATIM)
  target_sources(${ARG_TARGET} PRIVATE ${out})
endfunction()
