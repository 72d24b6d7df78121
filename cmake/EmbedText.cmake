# cmake -DINPUT=<file> -DOUTPUT=<header> -DNAMESPACE=<ns> -DNAME=<identifier> -P EmbedText.cmake
# Writes a header that holds the file's text as `inline constexpr std::string_view NAME` in
# namespace NAMESPACE, so a page stays an ordinary file to edit and still ships inside the
# binary. Runs at build time (add_custom_command), so an edit rebuilds without a re-configure.
# The text is a char array, its view sized by sizeof: a string_view made from a pointer counts
# its length in constant evaluation, which GCC gives up on for a file of 850 kB (three.js).
file(READ "${INPUT}" text)
set(delimiter "hiltwin_embed")
string(FIND "${text}" ")${delimiter}\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )${delimiter}\"")
endif()
file(WRITE "${OUTPUT}"
  "// Generated from ${INPUT} by cmake/EmbedText.cmake: edit that file instead.\n"
  "#pragma once\n#include <string_view>\nnamespace ${NAMESPACE} {\n"
  "inline constexpr char ${NAME}Text[] = R\"${delimiter}(${text})${delimiter}\";\n"
  "inline constexpr std::string_view ${NAME}{${NAME}Text, sizeof(${NAME}Text) - 1};\n"
  "}  // namespace ${NAMESPACE}\n")
