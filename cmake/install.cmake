# Installation and the Debian package (included last from the top-level CMakeLists.txt).
#
#   cmake --install build --prefix P      (no root needed for a P of one's own)
#   cd build && cpack -G DEB              (flexure_VERSION_ARCH.deb, installing into /usr)
#
# The layout, relative to the prefix; the executables find each other through it, from their
# own folder (/proc/self/exe), so an installed tree can be moved or copied elsewhere whole:
#   bin/flexure, bin/flexure-draw          flexure execs the flexure-draw beside it (cli/drawing_exec.cpp)
#   lib/flexure/libflexure-av.so           found as ../lib/flexure from bin/ (render/libav.cpp;
#                                          FLEXURE_AV_INSTALL_DIR)
#   FLEXURE_INSTALL_PYTHONDIR/flexure/     the Python package: python/flexure/*.py, the module
#                                          _flexure*.so and a copy of libflexure-av.so (the module
#                                          looks beside itself first)
#   share/man/man1/flexure.1.gz            generated from the executable's --help (cmake/manpage.cmake);
#                                          flexure-draw.1.gz links to it
#   share/doc/flexure/                     README.md and the documents of docs/
# Nothing installed refers to the build tree: the executables have no RPATH (every library they
# link is a system one), and the loader has no path of the build tree compiled in
# (tests/install/run.sh checks both).

# The man page, rewritten after every link of flexure (it is flexure's --help): part of the
# flexure target, so that every build that can be installed has it (and flexure is linked again
# when the page's script changes).
find_program(FLEXURE_GZIP gzip)
mark_as_advanced(FLEXURE_GZIP)
set(FLEXURE_MAN_DIR ${CMAKE_BINARY_DIR}/man)
file(MAKE_DIRECTORY ${FLEXURE_MAN_DIR})
add_custom_command(TARGET flexure POST_BUILD
  COMMAND ${CMAKE_COMMAND} -DFLEXURE=$<TARGET_FILE:flexure> -DOUT=${FLEXURE_MAN_DIR}/flexure.1
          -DGZIP=${FLEXURE_GZIP} -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/manpage.cmake
  COMMENT "Writing the man page flexure(1) from flexure --help"
  VERBATIM)
set_property(TARGET flexure APPEND PROPERTY LINK_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/cmake/manpage.cmake)

install(TARGETS flexure flexure-draw RUNTIME DESTINATION bin)
install(TARGETS flexure_libav LIBRARY DESTINATION ${FLEXURE_AV_INSTALL_DIR})
if(FLEXURE_GZIP)
  install(FILES ${FLEXURE_MAN_DIR}/flexure.1.gz ${FLEXURE_MAN_DIR}/flexure-draw.1.gz DESTINATION share/man/man1)
else()
  install(FILES ${FLEXURE_MAN_DIR}/flexure.1 DESTINATION share/man/man1)
endif()
install(FILES README.md DESTINATION share/doc/flexure)
install(DIRECTORY docs/ DESTINATION share/doc/flexure/docs FILES_MATCHING PATTERN "*.md" PATTERN "study" EXCLUDE)

# The Python package, where Debian's python3 keeps packages under a prefix: its sysconfig scheme
# deb_system (lib/python3/dist-packages: on sys.path for the prefix /usr, i.e. the .deb; any
# other prefix needs PYTHONPATH=PREFIX/lib/python3/dist-packages), posix_prefix elsewhere.
# -DFLEXURE_INSTALL_PYTHONDIR=lib/python3.11/dist-packages suits the prefix /usr/local.
if(FLEXURE_PYTHON)
  # The interpreter python/CMakeLists.txt built the module for.
  get_directory_property(flexure_python_exe DIRECTORY python DEFINITION Python_EXECUTABLE)
  execute_process(
    COMMAND ${flexure_python_exe} -c "import sys, sysconfig
s = 'deb_system' if 'deb_system' in sysconfig.get_scheme_names() else 'posix_prefix'
print(sysconfig.get_path('platlib', s, vars={'base': '', 'platbase': ''}).lstrip('/'))
v = sys.version_info
print('%d.%d' % (v[0], v[1]))
print('%d.%d' % (v[0], v[1] + 1))"
    OUTPUT_VARIABLE flexure_python_paths RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "flexure: ${flexure_python_exe} could not tell where Python packages are installed")
  endif()
  string(REPLACE "\n" ";" flexure_python_paths "${flexure_python_paths}")
  list(GET flexure_python_paths 0 flexure_python_dir)
  list(GET flexure_python_paths 1 flexure_python_version)
  list(GET flexure_python_paths 2 flexure_python_next)
  set(FLEXURE_INSTALL_PYTHONDIR "${flexure_python_dir}" CACHE STRING
      "Where the Python package flexure is installed, relative to the prefix")
  install(TARGETS flexure_python LIBRARY DESTINATION ${FLEXURE_INSTALL_PYTHONDIR}/flexure)
  install(TARGETS flexure_libav LIBRARY DESTINATION ${FLEXURE_INSTALL_PYTHONDIR}/flexure)
  install(DIRECTORY python/flexure/ DESTINATION ${FLEXURE_INSTALL_PYTHONDIR}/flexure
          FILES_MATCHING PATTERN "*.py" PATTERN "__pycache__" EXCLUDE)
endif()

# The Debian package: cpack -G DEB in the build folder. dpkg-shlibdeps finds the libraries'
# packages; the rest is named here.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME flexure)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "continuous motions of geometric constraint systems")
set(CPACK_PACKAGE_DESCRIPTION "flexure tells whether a geometric constraint system is rigid, and follows its
continuous motions: bar-joint frameworks in 2D and 3D, polytopes, body-hinge and body-bar
frameworks, angular frameworks, volume hypergraphs, caps on a sphere, frameworks on a surface,
rigid origami, and sticky disk and sphere packings. It analyses the start configuration (rank,
infinitesimal flexes, stresses, prestress stability, second-order rigidity, a proved verdict),
tracks the deformation path through singular points and draws it as PNG, SVG, PDF, TikZ, MP4
or GIF, offscreen. The package holds the flexure and flexure-draw commands, MP4 writing, the
Python module (import flexure) and the man page.")
# The maintainer: -DFLEXURE_PACKAGE_MAINTAINER="Name <address>", by default the author of the
# source's last commit.
if(NOT DEFINED FLEXURE_PACKAGE_MAINTAINER)
  find_package(Git QUIET)
  if(GIT_FOUND AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/.git)
    execute_process(COMMAND ${GIT_EXECUTABLE} -C ${CMAKE_CURRENT_SOURCE_DIR} log -1 "--format=%an <%ae>"
                    OUTPUT_VARIABLE flexure_author OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  endif()
  set(FLEXURE_PACKAGE_MAINTAINER "${flexure_author}" CACHE STRING "The Debian package's Maintainer (Name <address>)")
endif()
set(CPACK_PACKAGE_CONTACT "${FLEXURE_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${FLEXURE_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_STRIP_FILES ON)
# The labels' default font (render/text.cpp), and what the Python package imports.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "fonts-dejavu-core")
if(FLEXURE_PYTHON)
  # The module is built for this interpreter's version only (_flexure.cpython-3XY-...so).
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS
         ", python3 (>= ${flexure_python_version}), python3 (<< ${flexure_python_next}), python3-numpy")
  set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-networkx")
endif()
include(CPack)
