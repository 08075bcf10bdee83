# Writes tools/version.h with the commit the sources are at, on every build (not only at configure time, which would
# leave the provenance of every later build naming an older commit). configure_file rewrites the header only when its
# text changes, so a build at the same commit recompiles nothing.
# tools/CMakeLists.txt includes it at configure time and runs it with -P before each build:
#   cmake -DREFRAY_VERSION_SOURCE_DIR=... -DREFRAY_VERSION_INPUT=version.h.in -DREFRAY_VERSION_OUTPUT=.../version.h
#         -DPROJECT_VERSION=... -P RefrayVersion.cmake
execute_process(COMMAND git rev-parse --short=12 HEAD
                WORKING_DIRECTORY ${REFRAY_VERSION_SOURCE_DIR}
                OUTPUT_VARIABLE REFRAY_GIT_COMMIT OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(NOT REFRAY_GIT_COMMIT)
  set(REFRAY_GIT_COMMIT "unknown")
endif()
configure_file(${REFRAY_VERSION_INPUT} ${REFRAY_VERSION_OUTPUT} @ONLY)
