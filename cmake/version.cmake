# The version users see, from one place: the project's VERSION (CMakeLists.txt) at a release (a
# commit tagged v<VERSION>), else <VERSION>+g<commit> between releases (PEP 440's local version,
# SemVer's build metadata, a Debian version). `specdeform --version`, specdeform.__version__,
# the wheel, the .deb and the pkg-config file say it (src/version.cpp.in); bl_info and the
# extension manifest, which take numbers only, say VERSION (tests/install checks they agree).
# Where there is no git (an sdist), setup.py passes it as -DSPECDEFORM_VERSION_FULL.
set(SPECDEFORM_VERSION_FULL "" CACHE STRING "the version to report (default: from git)")
set(version_full ${SPECDEFORM_VERSION_FULL})
if(NOT version_full)
  set(version_full ${PROJECT_VERSION})
  find_package(Git QUIET)
  if(GIT_FOUND AND EXISTS ${PROJECT_SOURCE_DIR}/.git)
    execute_process(COMMAND ${GIT_EXECUTABLE} describe --tags --exact-match
                            --match v${PROJECT_VERSION} HEAD
                    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} RESULT_VARIABLE tagged
                    OUTPUT_QUIET ERROR_QUIET)
    execute_process(COMMAND ${GIT_EXECUTABLE} rev-parse --short=8 HEAD
                    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} OUTPUT_VARIABLE commit
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(NOT tagged EQUAL 0 AND commit)
      set(version_full ${PROJECT_VERSION}+g${commit})
    endif()
    # A new commit configures again (HEAD, the branch it names, the packed refs).
    execute_process(COMMAND ${GIT_EXECUTABLE} rev-parse --absolute-git-dir
                    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} OUTPUT_VARIABLE git_dir
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    execute_process(COMMAND ${GIT_EXECUTABLE} symbolic-ref -q HEAD
                    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} OUTPUT_VARIABLE branch
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    foreach(file HEAD ${branch} packed-refs)
      if(EXISTS ${git_dir}/${file})
        set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${git_dir}/${file})
      endif()
    endforeach()
  endif()
endif()
set(SPECDEFORM_VERSION ${version_full})
message(STATUS "specdeform ${SPECDEFORM_VERSION}")
