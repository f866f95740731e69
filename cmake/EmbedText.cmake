# Generates a C++ source defining `const char* FUNCTION()` that returns the text of INPUT.
# Usage: cmake -DINPUT=... -DOUTPUT=... -DNAMESPACE=... -DFUNCTION=... -P EmbedText.cmake
file(READ "${INPUT}" text)
string(FIND "${text}" ")solidtex_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter")
endif()
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/EmbedText.cmake; do not edit.\nnamespace ${NAMESPACE} {\nconst char* ${FUNCTION}() {\n  return R\"solidtex_embed(${text})solidtex_embed\";\n}\n}  // namespace ${NAMESPACE}\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
