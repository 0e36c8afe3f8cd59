# HANDCENTRIC_FUZZ=ON builds the libFuzzer targets of tests/fuzz (one per parser of outside data).
# libFuzzer ships with clang only (Debian: clang-14 and libfuzzer-14-dev), so any other compiler
# is refused at configure time rather than failing at link time.
#
#   CXX=clang++ cmake -S . -B build-fuzz -DHANDCENTRIC_FUZZ=ON \
#     -DHANDCENTRIC_SANITIZE=address,undefined
#
# Every project target is compiled with coverage feedback (-fsanitize=fuzzer-no-link), so the
# fuzzer is guided by the branches of the library it calls, not only by those of the target.
# Only the fuzz targets link libFuzzer's main; scripts/fuzz.sh builds and runs them.
option(HANDCENTRIC_FUZZ "Build the libFuzzer targets of tests/fuzz (needs clang)" OFF)

if(HANDCENTRIC_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR
      "HANDCENTRIC_FUZZ=ON needs clang (libFuzzer is part of clang), but the C++ compiler is "
      "${CMAKE_CXX_COMPILER_ID} (${CMAKE_CXX_COMPILER}). Configure a fresh build folder with "
      "CXX=clang++ (Debian: apt-get install clang libfuzzer-14-dev), or use scripts/fuzz.sh.")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
  # HandcentricSanitize.cmake turns off a GCC-only warning (maybe-uninitialized) that clang
  # does not know, and -Werror would make clang's "unknown warning option" fatal.
  add_compile_options(-Wno-unknown-warning-option)
  add_link_options(-fsanitize=fuzzer-no-link)
  message(STATUS "handcentric: libFuzzer targets in tests/fuzz, coverage on every project target")
endif()
