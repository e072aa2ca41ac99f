# Where `cmake --install` puts things (docs/install.md), relative to the prefix:
#   bin/fourierflare, share/fourierflare/{lenses,glass,plates}, share/man/man1/fourierflare.1, and the
#   Python module in FF_PYTHON_INSTALL_DIR, where the interpreter it was built for looks.
# The binaries find their data from their own folder (src/core/install_paths.cpp), through the
# relative paths computed here, so an installed tree can be moved (a .deb unpacked into a root).
include(GNUInstallDirs)
set(FF_DATA_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/fourierflare)

if(FF_BUILD_PYTHON AND NOT DEFINED FF_PYTHON_INSTALL_DIR)
  # Debian's interpreters look in <prefix>/lib/python3.X/dist-packages for /usr/local and /usr (the
  # posix_local and deb_system schemes); others in their posix_prefix platlib (site-packages).
  execute_process(
    COMMAND ${Python3_EXECUTABLE} -c
      "import sysconfig,sys; v='python%d.%d' % sys.version_info[:2]; s=sysconfig.get_scheme_names(); print(f'lib/{v}/dist-packages' if 'deb_system' in s else sysconfig.get_path('platlib','posix_prefix',vars={'base':'/P','platbase':'/P'})[3:])"
    OUTPUT_VARIABLE ff_python_dir OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE ff_python_rc)
  if(NOT ff_python_rc EQUAL 0 OR ff_python_dir STREQUAL "")
    message(FATAL_ERROR "could not ask ${Python3_EXECUTABLE} where its modules go; set FF_PYTHON_INSTALL_DIR")
  endif()
  set(FF_PYTHON_INSTALL_DIR ${ff_python_dir} CACHE STRING
      "Where the Python module is installed, relative to the prefix (default: where the interpreter looks)")
endif()

# The data folder relative to bin/ and to the Python module's folder (both relative to the prefix).
file(RELATIVE_PATH FF_DATA_FROM_BIN /P/${CMAKE_INSTALL_BINDIR} /P/${FF_DATA_INSTALL_DIR})
if(FF_BUILD_PYTHON)
  file(RELATIVE_PATH FF_DATA_FROM_PYTHON /P/${FF_PYTHON_INSTALL_DIR} /P/${FF_DATA_INSTALL_DIR})
else()
  set(FF_DATA_FROM_PYTHON ${FF_DATA_FROM_BIN})
endif()
