# cmake --install: the room libraries (cmake/rooms.cmake) as jsatlas::<room>
# (jsatlas::engine, jsatlas::geometry, ..., jsatlas::pictures) and jsatlas_flags
# as jsatlas::flags, the public headers under <prefix>/include/jsatlas with their
# sub-folders (still included as "engine/tape.h", "io/geometry/mesh.h"), the
# jsatlas binary, and a package config so that another project can write
#   find_package(jsatlas REQUIRED)
#   target_link_libraries(app PRIVATE jsatlas::model jsatlas::io)
# Component "development" is everything but the binary (component "cli").
include(CMakePackageConfigHelpers)
set(JSATLAS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/jsatlas)

set_target_properties(jsatlas_flags PROPERTIES EXPORT_NAME flags)
set(room_targets)
foreach(room ${jsatlas_rooms})
  set_target_properties(jsatlas_${room} PROPERTIES EXPORT_NAME ${room})
  list(APPEND room_targets jsatlas_${room})
endforeach()

install(TARGETS jsatlas_flags ${room_targets}
        EXPORT jsatlasTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development)
install(TARGETS jsatlas RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cli)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine ${PROJECT_SOURCE_DIR}/io ${PROJECT_SOURCE_DIR}/losses
                  ${PROJECT_SOURCE_DIR}/model
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/jsatlas COMPONENT development
        FILES_MATCHING PATTERN "*.h")

install(EXPORT jsatlasTargets NAMESPACE jsatlas:: DESTINATION ${JSATLAS_CMAKE_DIR}
        COMPONENT development)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/jsatlasConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/jsatlasConfig.cmake
                              INSTALL_DESTINATION ${JSATLAS_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/jsatlasConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/jsatlasConfig.cmake ${PROJECT_BINARY_DIR}/jsatlasConfigVersion.cmake
        DESTINATION ${JSATLAS_CMAKE_DIR} COMPONENT development)
