# Interface target carrying the project's warning flags; every FourierFlare target links it.
add_library(ff_warnings INTERFACE)
add_library(ff::warnings ALIAS ff_warnings)
target_compile_options(ff_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                             -Wconversion -Wno-sign-conversion)
if(FF_WERROR)
  target_compile_options(ff_warnings INTERFACE -Werror)
endif()
# GCC 12 reports false -Wrestrict positives at -O3 inside std::string's operator+ (GCC bug 105651,
# fixed in GCC 13); silence only that warning, only on the affected compiler.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12
   AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(ff_warnings INTERFACE -Wno-restrict)
endif()
