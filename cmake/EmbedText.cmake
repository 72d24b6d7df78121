# cmake -DINPUT=<file> -DOUTPUT=<header> -DNAMESPACE=<ns> -DNAME=<identifier> -P EmbedText.cmake
# Writes a header that holds the file's text as `inline constexpr std::string_view NAME` in
# namespace NAMESPACE, so a page stays an ordinary file to edit and still ships inside the
# binary. Runs at build time (add_custom_command), so an edit rebuilds without a re-configure.
file(READ "${INPUT}" text)
set(delimiter "hiltwin_embed")
string(FIND "${text}" ")${delimiter}\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )${delimiter}\"")
endif()
file(WRITE "${OUTPUT}"
  "// Generated from ${INPUT} by cmake/EmbedText.cmake: edit that file instead.\n"
  "#pragma once\n#include <string_view>\nnamespace ${NAMESPACE} {\n"
  "inline constexpr std::string_view ${NAME} = R\"${delimiter}(${text})${delimiter}\";\n"
  "}  // namespace ${NAMESPACE}\n")
