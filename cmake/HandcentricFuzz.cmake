# HANDCENTRIC_FUZZ=ON builds the libFuzzer targets of tests/fuzz (one per parser of outside data).
# libFuzzer ships with clang only (Debian: clang-14 and libfuzzer-14-dev), so any other compiler
# is refused at configure time rather than failing at link time.
#
#   CXX=clang++ cmake -S . -B build-fuzz -DHANDCENTRIC_FUZZ=ON \
#     -DHANDCENTRIC_SANITIZE=address,undefined
#
# Coverage feedback (-fsanitize=fuzzer-no-link) guides the fuzzer by the branches of the library
# it calls, not only by those of the target. HANDCENTRIC_FUZZ_COVERAGE says where:
#   all      every project target (scripts/fuzz.sh's own tree, the default);
#   parsers  only the files that parse outside data (HANDCENTRIC_FUZZ_PARSER_SOURCES, each
#            compiled on its own, outside the unity batches), for a tree that also runs the test
#            suites: the counters and comparison hooks made the sanitizer run's tests 1.5-2.8x
#            slower everywhere else (scripts/sanitize.sh).
# Only the fuzz targets link libFuzzer's main; scripts/fuzz.sh builds and runs them.
option(HANDCENTRIC_FUZZ "Build the libFuzzer targets of tests/fuzz (needs clang)" OFF)
set(HANDCENTRIC_FUZZ_COVERAGE "all" CACHE STRING
    "Where the fuzz targets get coverage feedback: all (every target) or parsers")
set_property(CACHE HANDCENTRIC_FUZZ_COVERAGE PROPERTY STRINGS all parsers)
# What the five fuzz targets parse: demo files, model files, plug-in replies and their arrays,
# the geometry's validating constructors, and recorded observations (.npz and JSON Lines).
set(HANDCENTRIC_FUZZ_PARSER_SOURCES
  sim/src/demos.cpp sim/src/demo_file.cpp
  policy/src/model_file.cpp policy/src/binary_io.cpp
  props/src/transport/plugin_protocol.cpp props/src/wire_arrays.cpp
  core/src/rigid_transform.cpp core/src/rotation.cpp
  props/src/observation/npz.cpp props/src/observation/recorded.cpp)

if(HANDCENTRIC_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR
      "HANDCENTRIC_FUZZ=ON needs clang (libFuzzer is part of clang), but the C++ compiler is "
      "${CMAKE_CXX_COMPILER_ID} (${CMAKE_CXX_COMPILER}). Configure a fresh build folder with "
      "CXX=clang++ (Debian: apt-get install clang libfuzzer-14-dev), or use scripts/fuzz.sh.")
  endif()
  if(HANDCENTRIC_FUZZ_COVERAGE STREQUAL "all")
    add_compile_options(-fsanitize=fuzzer-no-link)
  elseif(NOT HANDCENTRIC_FUZZ_COVERAGE STREQUAL "parsers")
    message(FATAL_ERROR "HANDCENTRIC_FUZZ_COVERAGE is '${HANDCENTRIC_FUZZ_COVERAGE}': use all "
                        "(every target) or parsers (the files of HANDCENTRIC_FUZZ_PARSER_SOURCES)")
  endif()
  # HandcentricSanitize.cmake turns off a GCC-only warning (maybe-uninitialized) that clang
  # does not know, and -Werror would make clang's "unknown warning option" fatal.
  add_compile_options(-Wno-unknown-warning-option)
  add_link_options(-fsanitize=fuzzer-no-link)
  message(STATUS "handcentric: libFuzzer targets in tests/fuzz, coverage: "
                 "${HANDCENTRIC_FUZZ_COVERAGE}")
endif()

# Called once every library target exists (tests/fuzz/CMakeLists.txt): with coverage on the
# parsers only, gives each parser source its own compiler run with the coverage flag.
function(handcentric_fuzz_parser_coverage)
  if(NOT HANDCENTRIC_FUZZ_COVERAGE STREQUAL "parsers")
    return()
  endif()
  foreach(source IN LISTS HANDCENTRIC_FUZZ_PARSER_SOURCES)
    string(REGEX MATCH "^[a-z]+" module "${source}")
    set(path "${PROJECT_SOURCE_DIR}/${source}")
    if(NOT EXISTS "${path}")
      message(FATAL_ERROR "HANDCENTRIC_FUZZ_PARSER_SOURCES names ${source}, which does not exist: "
                          "update the list in cmake/HandcentricFuzz.cmake")
    endif()
    set_property(SOURCE "${path}" TARGET_DIRECTORY handcentric_${module}
                 PROPERTY SKIP_UNITY_BUILD_INCLUSION ON)
    set_property(SOURCE "${path}" TARGET_DIRECTORY handcentric_${module}
                 APPEND PROPERTY COMPILE_OPTIONS -fsanitize=fuzzer-no-link)
  endforeach()
endfunction()
