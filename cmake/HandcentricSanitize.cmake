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
# HANDCENTRIC_SANITIZE_PLAIN: targets of a sanitized build compiled without instrumentation at
# -O0 (handcentric_sanitize_plain() below, called once every target exists): scripts/sanitize.sh
# names the orchestration layer (experiments, the command and their tests), a third of the
# sanitized build's time, so that the libraries' instrumented tests fit CI's time.
set(HANDCENTRIC_SANITIZE_PLAIN "" CACHE STRING
    "With HANDCENTRIC_SANITIZE: a semicolon list of targets compiled uninstrumented at -O0")

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

# Called at the end of the top-level CMakeLists, when every target exists: the targets of
# HANDCENTRIC_SANITIZE_PLAIN compiled without instrumentation (their code is not checked; the
# libraries they call are) and at -O0 (three times faster to compile than -O1 with the
# sanitizers). They still link the sanitizer runtimes, as every program of the tree does.
function(handcentric_sanitize_plain)
  if(NOT HANDCENTRIC_SANITIZE)
    return()
  endif()
  foreach(target IN LISTS HANDCENTRIC_SANITIZE_PLAIN)
    if(NOT TARGET ${target})
      message(FATAL_ERROR "HANDCENTRIC_SANITIZE_PLAIN: no target '${target}'")
    endif()
    target_compile_options(${target} PRIVATE -fno-sanitize=all -O0)
  endforeach()
  if(HANDCENTRIC_SANITIZE_PLAIN)
    message(STATUS "handcentric: uninstrumented at -O0: ${HANDCENTRIC_SANITIZE_PLAIN}")
  endif()
endfunction()
