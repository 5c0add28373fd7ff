// tinyobjloader compiled into the OBJ fuzz target itself, with the same scalar
// as the library's tinyobjloader_double, so that libFuzzer sees coverage inside
// the OBJ parser and ASan checks its memory accesses (the Debian shared library
// is not instrumented). These definitions take precedence over the .so's.
#define TINYOBJLOADER_USE_DOUBLE
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
