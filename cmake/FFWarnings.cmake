# Interface target carrying the project's warning flags; every FourierFlare target links it.
add_library(ff_warnings INTERFACE)
add_library(ff::warnings ALIAS ff_warnings)
target_compile_options(ff_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                             -Wconversion -Wno-sign-conversion)
if(FF_WERROR)
  target_compile_options(ff_warnings INTERFACE -Werror)
endif()
