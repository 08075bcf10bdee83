# One warnings target that every refray target links.
add_library(refray_warnings INTERFACE)
target_compile_options(refray_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                                 -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough)

add_library(refray_sanitizers INTERFACE)
if(REFRAY_SANITIZE)
  target_compile_options(refray_sanitizers INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                     -fno-sanitize-recover=undefined)
  target_link_options(refray_sanitizers INTERFACE -fsanitize=address,undefined)
endif()
target_link_libraries(refray_warnings INTERFACE refray_sanitizers)
