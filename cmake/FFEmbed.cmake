# ff_embed_files(<target> <namespace> <files...>)
# Generates a source file that holds each file's bytes as a constant array, plus a lookup function
#   std::string_view <namespace>::embedded(std::string_view name)   (name = the file's base name)
# so that data (glass catalogues, shaders) ships inside the binary and the tool runs from any folder.
function(ff_embed_files target ns)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/${target}_embedded.cpp)
  string(REPLACE ";" "|" files "${ARGN}") # a list would split into several command arguments
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DNS=${ns} -DFILES=${files}
            -P ${PROJECT_SOURCE_DIR}/cmake/FFEmbedScript.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/FFEmbedScript.cmake
    COMMENT "Embedding data into ${target}"
    VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()
