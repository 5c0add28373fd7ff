# cmake -DIN=file -DOUT=file.cpp -DNAME=symbol -P embed_text.cmake
# Writes OUT defining `const char* const jsa::NAME` = the bytes of IN, so that
# a template (the viewer page) is part of the binary and needs no file at run time.
file(READ "${IN}" text)
string(FIND "${text}" ")jsatlas_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${IN} contains the raw-string delimiter )jsatlas_embed\"")
endif()
file(WRITE "${OUT}.tmp" "// Generated from ${IN} by cmake/embed_text.cmake; do not edit.\n"
     "namespace jsa {\nextern const char* const ${NAME};\n"
     "const char* const ${NAME} = R\"jsatlas_embed(${text})jsatlas_embed\";\n}  // namespace jsa\n")
file(RENAME "${OUT}.tmp" "${OUT}")
