# The find_package test: install the built jsatlas (development component) into
# a fresh prefix, then configure, build and run test/find_package as a separate
# project that only knows that prefix. Run by ctest as
#   cmake -DJSATLAS_SOURCE_DIR=... -DJSATLAS_BINARY_DIR=... -DWORK_DIR=... -P run.cmake
foreach(var JSATLAS_SOURCE_DIR JSATLAS_BINARY_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run.cmake needs -D${var}=...")
  endif()
endforeach()
set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/build)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${what}:\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "find_package test: ${what} failed (exit ${rc})")
  endif()
endfunction()

step("install into ${prefix}"
     ${CMAKE_COMMAND} --install ${JSATLAS_BINARY_DIR} --prefix ${prefix} --component development)
# The consumer is built with the generator and compiler that built jsatlas.
set(generator_args)
if(CMAKE_GENERATOR)
  list(APPEND generator_args -G ${CMAKE_GENERATOR})
endif()
if(CMAKE_CXX_COMPILER)
  list(APPEND generator_args -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER})
endif()
# CMAKE_FIND_USE_PACKAGE_REGISTRY=OFF and the prefix as the only hint: the
# consumer must find jsatlas through the installed config, not the build tree.
step("configure the consumer"
     ${CMAKE_COMMAND} -S ${JSATLAS_SOURCE_DIR}/test/find_package -B ${build} ${generator_args}
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${build}/CMakeCache.txt found REGEX "^jsatlas_DIR:")
if(NOT found MATCHES "${prefix}/")
  message(FATAL_ERROR "find_package test: jsatlas was found outside the install prefix (${found})")
endif()
step("build the consumer" ${CMAKE_COMMAND} --build ${build})
step("run the consumer" ${build}/consumer ${WORK_DIR}/consumer_cube.obj)
