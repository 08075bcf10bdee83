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
# Compiler bugs that change refray's numbers. GCC's SLP vectorizer (seen with GCC 12.2 at -O2 and -O3): when it puts
# two components of double(float(x)) in one vector, value numbering folds the vector conversion pair back to x, so
# the widened copy keeps the unrounded double and release builds compute other numbers than dev builds. Off for
# every refray target; it costs no measurable render time. Reproducer: tests/stability/build_mode_test.cpp;
# evidence: docs/numerical-stability.md, "Build modes".
add_library(refray_compiler_workarounds INTERFACE)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(refray_compiler_workarounds INTERFACE -fno-tree-slp-vectorize)
endif()
target_link_libraries(refray_warnings INTERFACE refray_sanitizers refray_compiler_workarounds)

# The wave executor's lane math (procedural/math/lanes.h) keeps 16 float lanes in SIMD registers only where the
# target has wide vectors: refray is compiled for the machine that builds it (tools/setup.sh builds from source
# where it runs), as lavapipe compiles its shaders for the CPU it runs on. Floating-point contraction stays off, so
# that no multiply and add fuse into an FMA the scalar code does not have: every result is the same as without
# -march (tests/stability). -Wno-psabi: GCC notes that passing wide vectors changed ABI in GCC 4.x, which is
# nothing refray crosses. REFRAY_NATIVE_ARCH=OFF builds for any x86-64 (tools/gpu_bundle.sh, for another machine).
option(REFRAY_NATIVE_ARCH "Compile for the building machine's CPU (-march=native)" ON)
add_library(refray_target_cpu INTERFACE)
# A target with the property REFRAY_CONTRACT_FMA (procedural/CMakeLists.txt: refray_procedural_fma) contracts instead.
target_compile_options(refray_target_cpu INTERFACE
                       $<IF:$<BOOL:$<TARGET_PROPERTY:REFRAY_CONTRACT_FMA>>,-ffp-contract=fast,-ffp-contract=off> -Wno-psabi)
if(REFRAY_NATIVE_ARCH)
  include(CheckCXXCompilerFlag)
  check_cxx_compiler_flag(-march=native REFRAY_HAVE_MARCH_NATIVE)
  if(REFRAY_HAVE_MARCH_NATIVE)
    target_compile_options(refray_target_cpu INTERFACE -march=native)
  endif()
endif()
target_link_libraries(refray_warnings INTERFACE refray_target_cpu)
