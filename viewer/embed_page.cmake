# cmake -DOUT=file.cpp -DPAGE=viewer/page.html -P embed_page.cmake
# Writes a C++ source returning the viewer's page, so the binary serves no file from disk.
file(READ "${PAGE}" text)
string(FIND "${text}" ")flexure_page\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "page.html contains the raw-string delimiter")
endif()
set(body "// Generated from viewer/page.html by viewer/embed_page.cmake. Do not edit.\n")
string(APPEND body "#include \"viewer/server.h\"\n\nnamespace flexure::viewer {\n\n")
string(APPEND body "const char* viewerPage() {\n  return R\"flexure_page(${text})flexure_page\";\n}\n\n")
string(APPEND body "}  // namespace flexure::viewer\n")
file(WRITE "${OUT}.tmp" "${body}")
file(RENAME "${OUT}.tmp" "${OUT}")
