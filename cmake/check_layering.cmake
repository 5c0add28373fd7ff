# Fails when a file of room ROOM includes a header of a room it may not use
# (the table is cmake/rooms.cmake). Run at build time, before the room compiles:
#   cmake -DROOM=geometry -DSOURCE_DIR=<top> -DSTAMP=<file> -P cmake/check_layering.cmake
# Includes in quotes must name a room's header from the top ("io/geometry/mesh.h");
# <...> includes are other libraries and are not checked. On success, touches STAMP.
cmake_minimum_required(VERSION 3.18)  # script mode: IN_LIST, POP_FRONT
foreach(var ROOM SOURCE_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_layering.cmake needs -D${var}=...")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/rooms.cmake)
if(NOT ROOM IN_LIST jsatlas_rooms)
  message(FATAL_ERROR "layering: unknown room '${ROOM}' (rooms: ${jsatlas_rooms})")
endif()

jsatlas_room_closure(${ROOM} allowed)
set(allowed_text "${allowed}")
string(REPLACE ";" ", " allowed_text "${allowed_text}")
if(allowed_text STREQUAL "")
  set(allowed_text "nothing")
endif()

set(dir ${jsatlas_room_dir_${ROOM}})
file(GLOB files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/${dir}/*.h ${SOURCE_DIR}/${dir}/*.cpp)
list(SORT files)
set(errors 0)
foreach(file ${files})
  file(STRINGS ${SOURCE_DIR}/${file} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line ${lines})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]*)\".*" "\\1" header "${line}")
    jsatlas_room_of(${header} room)
    if(room STREQUAL "")
      message("layering: ${file} includes ${header}, which is in no room "
              "(include from the top: \"io/geometry/mesh.h\", never bin/ or test/)")
      math(EXPR errors "${errors} + 1")
    elseif(NOT room STREQUAL ROOM AND NOT room IN_LIST allowed)
      message("layering: ${file} includes ${header}, but ${ROOM} may use only: ${allowed_text}")
      math(EXPR errors "${errors} + 1")
    endif()
  endforeach()
endforeach()
if(errors GREATER 0)
  message(FATAL_ERROR "layering: ${errors} include(s) break the rooms of cmake/rooms.cmake "
                      "(docs/README.md, \"the rooms\")")
endif()
if(DEFINED STAMP)
  file(WRITE ${STAMP} "")  # creates the folder too
endif()
