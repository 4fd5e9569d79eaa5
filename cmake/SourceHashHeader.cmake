# diefill_source_hash(NAME OUTPUT COMMENT SOURCES...): OUTPUT, a header defining NAME as the
# SHA-256 of SOURCES (cmake/SourceHash.cmake), written again whenever one of them changes, so that
# a cache keyed by it (an SDF, a settled shoe) is never reused after the code that made it changed.
function(diefill_source_hash name output comment)
  string(REPLACE ";" "|" list "${ARGN}")
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DNAME=${name} "-DSOURCES=${list}" -DOUTPUT=${output} -P ${PROJECT_SOURCE_DIR}/cmake/SourceHash.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/SourceHash.cmake
    COMMENT "${comment}" VERBATIM)
endfunction()
