# `cmake --install build --prefix P` (DESTDIR honoured) puts everything under P:
#   bin/specdeform                        the program (when built)
#   share/specdeform/web                  the editor's page, which the installed program serves
#   lib/libspecdeform.a, include/specdeform  the library and its public headers
#   lib/cmake/specdeform                  find_package(specdeform CONFIG) -> specdeform::core
#   lib/pkgconfig/specdeform.pc           pkg-config --cflags --libs specdeform
# The Python package and the Blender add-on go under P as well (python/CMakeLists.txt,
# blender/CMakeLists.txt) unless their own install options point elsewhere.
include(CMakePackageConfigHelpers)

set(SPECDEFORM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/specdeform)

install(TARGETS specdeform_core EXPORT specdeformTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/specdeform
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT development)
install(EXPORT specdeformTargets NAMESPACE specdeform:: DESTINATION ${SPECDEFORM_CMAKE_DIR}
        COMPONENT development)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/specdeformConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/specdeformConfig.cmake
                              INSTALL_DESTINATION ${SPECDEFORM_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/specdeformConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/specdeformConfig.cmake
              ${PROJECT_BINARY_DIR}/specdeformConfigVersion.cmake
        DESTINATION ${SPECDEFORM_CMAKE_DIR} COMPONENT development)

# pkg-config: the static library with every library it links (-l names of the found paths).
set(pc_libs "")
foreach(library ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY} ${BLAS_LIBRARY})
  get_filename_component(name ${library} NAME_WE)
  string(REGEX REPLACE "^lib" "" name ${name})
  string(APPEND pc_libs " -l${name}")
endforeach()
configure_file(${CMAKE_CURRENT_LIST_DIR}/specdeform.pc.in ${PROJECT_BINARY_DIR}/specdeform.pc
               @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/specdeform.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT development)

if(TARGET specdeform)
  install(TARGETS specdeform RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT program)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/web/dist/
          DESTINATION ${CMAKE_INSTALL_DATADIR}/specdeform/web COMPONENT program)
endif()
