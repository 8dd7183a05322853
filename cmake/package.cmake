# `cpack -G DEB` in the build folder makes two packages for Debian 12, for
# `apt install ./specdeform_*.deb ./specdeform-dev_*.deb`:
#   specdeform      /usr/bin/specdeform, /usr/share/specdeform/web    the program and the page
#                   /usr/lib/python3/dist-packages/specdeform         the module, for Debian's
#                                                                     python3 (byte-compiled by
#                                                                     postinst, cleaned by prerm)
#                   /usr/share/blender/scripts/addons/specdeform_blender  the add-on in Debian's
#                                                                     Blender's list (it imports
#                                                                     the module above)
#   specdeform-dev  /usr/lib/libspecdeform.a, /usr/include/specdeform, the library, its headers,
#                   /usr/lib/cmake/specdeform, /usr/lib/pkgconfig     its CMake and pkg-config
#                                                                     packages; Depends: the -dev
#                                                                     packages they find
# each with /usr/share/doc/<package>/copyright (machine-readable, GPL-3+) and changelog.gz. The
# compiled files link Debian's shared libraries; dpkg-shlibdeps names the packages that hold
# them. The components "deb_python", "deb_blender" and "deb_doc" are the packages' own
# (cmake --install leaves them out). The version is cmake/version.cmake's.
set(SPECDEFORM_DEB_MAINTAINER "specdeform developers <specdeform@users.noreply.github.com>"
    CACHE STRING "the Maintainer of the Debian packages: a name and an address")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME specdeform)
set(CPACK_PACKAGE_VERSION ${SPECDEFORM_VERSION})
set(CPACK_PACKAGE_CONTACT ${SPECDEFORM_DEB_MAINTAINER})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "interactive, detail-preserving deformation of large triangle meshes")
set(CPACK_PACKAGE_DESCRIPTION
    "The spectral method of Rong, Cao & Guo (The Visual Computer 2008): a library, a program,\
 a browser editor, Python bindings and a Blender add-on.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ONE_PER_GROUP)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME specdeform)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME specdeform-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libeigen3-dev (>= 3.4), libspectra-dev, nlohmann-json3-dev, \
libcgal-dev, libtinygltf-dev, libdraco-dev, libmeshoptimizer-dev, libsuitesparse-dev, \
libopenblas-dev | libblas-dev, libgmp-dev, libmpfr-dev")
# Debian's Description: CPack puts CPACK_PACKAGE_DESCRIPTION_SUMMARY first, then these lines.
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "The spectral method of Rong, Cao & Guo (The Visual Computer\n\
2008): a program that deforms OBJ, OFF, PLY, STL and glTF files and writes them\n\
back whole, a browser editor (specdeform edit), Python bindings for python3 and\n\
a Blender add-on.")
set(CPACK_DEBIAN_DEV_DESCRIPTION "The development files of specdeform: its C++ library (static), headers,\n\
and CMake and pkg-config packages (find_package(specdeform): specdeform::core).")
set(CPACK_COMPONENTS_ALL program development deb_doc deb_doc_dev)
if(TARGET _specdeform)
  # The module is built for one Python minor version (python/CMakeLists.txt).
  string(REPLACE "." ";" version ${SPECDEFORM_PYTHON_VERSION})
  list(GET version 1 minor)
  math(EXPR next_minor "${minor} + 1")
  string(REGEX REPLACE "[0-9]+$" ${next_minor} next_version ${SPECDEFORM_PYTHON_VERSION})
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "python3 (>= ${SPECDEFORM_PYTHON_VERSION}), \
python3 (<< ${next_version}), python3-numpy")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "python3-scipy")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "blender")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/deb/postinst
                                                 ${CMAKE_CURRENT_LIST_DIR}/deb/prerm)
  list(APPEND CPACK_COMPONENTS_ALL deb_python deb_blender)
endif()

# copyright and changelog.gz of each package (the changelog dated by the commit, reproducibly).
execute_process(COMMAND git log -1 --format=%aD WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                OUTPUT_VARIABLE SPECDEFORM_DEB_DATE OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(NOT SPECDEFORM_DEB_DATE)
  string(TIMESTAMP SPECDEFORM_DEB_DATE "%a, %d %b %Y %H:%M:%S +0000" UTC)
endif()
foreach(package specdeform specdeform-dev)
  set(doc ${PROJECT_BINARY_DIR}/deb/${package})
  set(CPACK_PACKAGE_NAME_FOR_CHANGELOG ${package})
  configure_file(${CMAKE_CURRENT_LIST_DIR}/deb/copyright.in ${doc}/copyright @ONLY)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/deb/changelog.in ${doc}/changelog @ONLY)
  execute_process(COMMAND gzip -9nf ${doc}/changelog)
  set(component deb_doc)
  if(package STREQUAL specdeform-dev)
    set(component deb_doc_dev)
  endif()
  install(FILES ${doc}/copyright ${doc}/changelog.gz DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${package}
          COMPONENT ${component} EXCLUDE_FROM_ALL)
endforeach()

include(CPack)
cpack_add_component_group(runtime)
cpack_add_component_group(dev)
foreach(component program deb_python deb_blender deb_doc)
  cpack_add_component(${component} GROUP runtime)
endforeach()
foreach(component development deb_doc_dev)
  cpack_add_component(${component} GROUP dev)
endforeach()
