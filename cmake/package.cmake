# `cpack -G DEB` in the build folder makes specdeform_<version>_amd64.deb for Debian 12, for
# `apt install ./specdeform_*.deb`:
#   /usr/bin/specdeform, /usr/share/specdeform/web         the program and the editor's page
#   /usr/lib/libspecdeform.a, /usr/include/specdeform,     the library, its headers, its CMake
#   /usr/lib/cmake/specdeform, /usr/lib/pkgconfig          and pkg-config packages
#   /usr/lib/python3/dist-packages/specdeform              the module, for Debian's python3
#   /usr/share/blender/scripts/addons/specdeform_blender   the add-on in Debian's Blender's list
#                                                          (it imports the module above)
# The compiled files link Debian's shared libraries; dpkg-shlibdeps names the packages that
# hold them. The components "deb_python" and "deb_blender" are the package's own copies of the
# module and the add-on (cmake --install leaves them out).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME specdeform)
set(CPACK_PACKAGE_CONTACT "specdeform developers")
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
# One package of these components (not the "python" and "blender" ones of cmake --install).
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ALL_COMPONENTS_IN_ONE)
set(CPACK_COMPONENTS_ALL program development)
if(TARGET _specdeform)
  # The module is built for one Python minor version (python/CMakeLists.txt).
  string(REPLACE "." ";" version ${SPECDEFORM_PYTHON_VERSION})
  list(GET version 1 minor)
  math(EXPR next_minor "${minor} + 1")
  string(REGEX REPLACE "[0-9]+$" ${next_minor} next_version ${SPECDEFORM_PYTHON_VERSION})
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= ${SPECDEFORM_PYTHON_VERSION}), \
python3 (<< ${next_version}), python3-numpy, python3-scipy")
  set(CPACK_DEBIAN_PACKAGE_SUGGESTS "blender")
  list(APPEND CPACK_COMPONENTS_ALL deb_python deb_blender)
endif()
include(CPack)
