# Install rules (docs/install.md): the CLI, the Python module, the bundled data, the man page, and
# the Debian package through CPack (scripts/package.sh).

install(TARGETS fourierflare RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(FF_BUILD_PYTHON)
  install(TARGETS ff_python LIBRARY DESTINATION ${FF_PYTHON_INSTALL_DIR})
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lenses/ DESTINATION ${FF_DATA_INSTALL_DIR}/lenses
        FILES_MATCHING PATTERN "*.lens" PATTERN "README.md")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/glass/ DESTINATION ${FF_DATA_INSTALL_DIR}/glass
        FILES_MATCHING PATTERN "*.glass")
install(FILES ${PROJECT_SOURCE_DIR}/data/night-street.exr ${PROJECT_SOURCE_DIR}/data/README.md
        DESTINATION ${FF_DATA_INSTALL_DIR})

# fourierflare(1), generated from the built CLI's own help.
find_package(Python3 COMPONENTS Interpreter REQUIRED)
set(FF_MAN_PAGE ${PROJECT_BINARY_DIR}/man/fourierflare.1)
add_custom_command(
  OUTPUT ${FF_MAN_PAGE}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/scripts/man-page.py $<TARGET_FILE:fourierflare> ${FF_MAN_PAGE}
  DEPENDS fourierflare ${PROJECT_SOURCE_DIR}/scripts/man-page.py
  COMMENT "Writing the man page from the CLI's help"
  VERBATIM)
add_custom_target(man_page ALL DEPENDS ${FF_MAN_PAGE})
install(FILES ${FF_MAN_PAGE} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

# The Debian package: `cpack -G DEB` in the build folder (scripts/package.sh). Its dependencies are
# computed by dpkg-shlibdeps from the libraries the binary and the module link, not listed by hand;
# python3 (the interpreter the module was built for) is the one added.
set(CPACK_PACKAGE_NAME fourierflare)
set(CPACK_PACKAGE_VENDOR "FourierFlare")
set(CPACK_PACKAGE_CONTACT "FourierFlare developers <fourierflare@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION "Lens flares from real lens prescriptions: ghosts traced through the lens, the iris's\ndiffraction, composited onto HDR plates. The fourierflare command, its Python module and\nthe bundled lenses and sample plate.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
if(FF_BUILD_PYTHON)
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}), python3 (<< ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}.99), python3-numpy")
endif()
set(CPACK_GENERATOR DEB)
include(CPack)
