# HANDCENTRIC_SANITIZE: a comma list of sanitizers (address, undefined) that instruments every
# target of this project: libraries, tests, the command and the benchmarks. Dependencies from
# Debian packages stay uninstrumented, which ASan and UBSan support.
#
#   cmake -S . -B build-asan -DHANDCENTRIC_SANITIZE=address,undefined
#
# UBSan is made fatal (-fno-sanitize-recover=all) so that a report fails the test that caused
# it instead of scrolling past. A sanitized build is for testing: its static libraries need the
# sanitizer runtimes at link time, so do not install it for downstream projects.
set(HANDCENTRIC_SANITIZE "" CACHE STRING
    "Sanitizers for every project target, a comma list of: address, undefined (empty: none)")

if(HANDCENTRIC_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "^(GNU|Clang)$")
    message(FATAL_ERROR "HANDCENTRIC_SANITIZE needs GCC or Clang, not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  string(REPLACE "," ";" handcentric_sanitizers "${HANDCENTRIC_SANITIZE}")
  foreach(sanitizer IN LISTS handcentric_sanitizers)
    if(NOT sanitizer MATCHES "^(address|undefined)$")
      message(FATAL_ERROR "HANDCENTRIC_SANITIZE: unknown sanitizer '${sanitizer}' in "
                          "'${HANDCENTRIC_SANITIZE}': use a comma list of address, undefined")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES handcentric_sanitizers)
  list(JOIN handcentric_sanitizers "," handcentric_sanitize_flag)
  # Frame pointers give ASan's fast unwinder whole stacks (reports and allocation sites).
  add_compile_options(-fsanitize=${handcentric_sanitize_flag} -fno-omit-frame-pointer
                      -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${handcentric_sanitize_flag} -fno-sanitize-recover=all)
  # GCC says __SANITIZE_ADDRESS__ under ASan, clang 14 only __has_feature(address_sanitizer),
  # which GCC's preprocessor cannot parse: one macro of our own for the code that must know
  # (the kernels' lane checks, the tests that cap a child's address space).
  if("address" IN_LIST handcentric_sanitizers)
    add_compile_definitions(HANDCENTRIC_ASAN=1)
  endif()
  # GCC 12 warns "may be used uninitialized" inside Eigen's fixed-size assignments once the
  # sanitizers' checks are inlined (a known false positive); the Release build keeps the warning.
  add_compile_options($<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
  message(STATUS "handcentric: sanitizers ${handcentric_sanitize_flag} on every project target")
endif()
