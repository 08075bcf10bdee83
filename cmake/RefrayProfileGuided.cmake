# Profile-guided and link-time optimisation of the release build (docs/performance.md, "Profile-guided and
# link-time optimisation"). Two presets share one profile directory:
# - `pgo-train` (REFRAY_PGO=GENERATE): an instrumented build; its refray renders the training scenes
#   (tools/pgo_train.sh), which writes the profile and a stamp naming it;
# - `release` (REFRAY_PGO=USE): compiled with that profile (GCC's -fprofile-use) and linked with LTO. Without a
#   profile (no stamp yet) it builds as a plain -O3 build and says so.
# Neither changes an image: neither flag lets the compiler reassociate or contract floating-point operations
# (-ffp-contract=off stays per function through LTO), so the renders are bit for bit the plain build's.
# The profile's files are named relative to the build directory (-fprofile-prefix-path), so the instrumented build and
# the optimised one, in two directories, meet on the same names. CMake watches the stamp: the first profile turns
# the flags on (everything compiles again); a later one reaches the files that compile again for their own changes,
# while the others keep what the profile before told GCC, which is as good for code that did not change.
# ccache (4.7) caches neither build: it counts -fprofile-update and -fprofile-prefix-path as unsupported options and
# hands those compilations to GCC.
set(REFRAY_PGO "OFF" CACHE STRING "Profile-guided optimisation: OFF, GENERATE (an instrumented build) or USE")
set_property(CACHE REFRAY_PGO PROPERTY STRINGS OFF GENERATE USE)
set(REFRAY_PGO_PROFILE "${CMAKE_SOURCE_DIR}/build/pgo-profile" CACHE PATH "The profile's directory (tools/pgo_train.sh)")

if(NOT REFRAY_PGO STREQUAL "OFF")
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    message(FATAL_ERROR "REFRAY_PGO=${REFRAY_PGO} needs GCC (its -fprofile-generate/-fprofile-use); this is "
                        "${CMAKE_CXX_COMPILER_ID}. Configure with -DREFRAY_PGO=OFF.")
  endif()
  set(refray_pgo_names "-fprofile-prefix-path=${CMAKE_BINARY_DIR}")
endif()

if(REFRAY_PGO STREQUAL "GENERATE")
  # Atomic counters: the training may render on several threads.
  add_compile_options("-fprofile-generate=${REFRAY_PGO_PROFILE}" -fprofile-update=atomic "${refray_pgo_names}")
  add_link_options("-fprofile-generate=${REFRAY_PGO_PROFILE}")
  message(STATUS "refray: instrumented build; its profile goes to ${REFRAY_PGO_PROFILE} (tools/pgo_train.sh)")
elseif(REFRAY_PGO STREQUAL "USE")
  set(stamp "${REFRAY_PGO_PROFILE}/profile.stamp")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${stamp}")
  if(EXISTS "${stamp}")
    file(READ "${stamp}" refray_pgo_id)
    string(STRIP "${refray_pgo_id}" refray_pgo_id)
    include(CheckIPOSupported)
    check_ipo_supported(RESULT refray_lto OUTPUT refray_lto_error LANGUAGES CXX)
    if(NOT refray_lto)
      message(FATAL_ERROR "refray: link-time optimisation is not available: ${refray_lto_error}")
    endif()
    set(CMAKE_INTERPROCEDURAL_OPTIMIZATION ON)
    # A function changed since the training keeps no profile (a warning, not an error); -fprofile-partial-training:
    # what the training never ran is optimised as without a profile, not for size.
    add_compile_options("-fprofile-use=${REFRAY_PGO_PROFILE}" -fprofile-partial-training "${refray_pgo_names}"
                        -Wno-missing-profile -Wno-error=coverage-mismatch)
    # GCC 12 warns at the LTO link about memcpy bounds it cannot relate across files (std::string's copies, a
    # ReportHit's attributes whose size is the checked type's): false alarms of its whole-program view, which the
    # per-file checks of every other build (-Wall -Wextra, -Werror in `ci`) still run on the same code.
    add_link_options(-Wno-stringop-overflow -Wno-stringop-overread)
    message(STATUS "refray: profile-guided (profile ${refray_pgo_id}) and link-time optimisation")
  else()
    message(STATUS "refray: no profile at ${REFRAY_PGO_PROFILE} (bash tools/pgo_train.sh makes one): building "
                   "without profile-guided and link-time optimisation")
  endif()
endif()
