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
# REFRAY_FUZZ (clang only, the `fuzz` preset): every target is instrumented for libFuzzer's coverage and runs
# under ASan + UBSan; the fuzz programs themselves link -fsanitize=fuzzer (tests/fuzz).
if(REFRAY_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "REFRAY_FUZZ needs clang for libFuzzer: use `cmake --preset fuzz` (apt-get install clang "
                        "libclang-rt-14-dev; tools/setup.sh does)")
  endif()
  target_compile_options(refray_sanitizers INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                                                     -fno-sanitize-recover=undefined)
  target_link_options(refray_sanitizers INTERFACE -fsanitize=address,undefined)
endif()
target_link_libraries(refray_warnings INTERFACE refray_sanitizers)
