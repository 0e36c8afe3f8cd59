# handcentric_library(<module> SOURCES ... DEPS ...)
# One CMake library per folder, aliased and exported as handcentric::<module>.
# Warnings are errors on project code only (PRIVATE), never pushed onto downstream users.
function(handcentric_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror)
endfunction()

function(handcentric_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target handcentric_${module})
  add_library(${target} ${ARG_SOURCES})
  add_library(handcentric::${module} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module}
                                             OUTPUT_NAME handcentric_${module})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  handcentric_warnings(${target})
  # errno is never read: lets sqrt/sin/cos inline and fuse (no ABI or result change).
  target_compile_options(${target} PRIVATE -fno-math-errno)
  # One export set per module: find_package(handcentric COMPONENTS core props) loads only those
  # modules and looks only for their dependencies (handcentricConfig.cmake.in).
  install(TARGETS ${target} EXPORT handcentric_${module}Targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT handcentric_${module}Targets NAMESPACE handcentric::
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/handcentric)
endfunction()

# handcentric_test(<name> SOURCES ... DEPS ... LABELS ...): one Catch2 executable per folder.
# Every TEST_CASE carries exactly one tag among LABELS ([unit], [property], [proofs],
# [experiment]); each tag becomes the ctest label of its cases, so `ctest -L property` works.
function(handcentric_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  # Catch's main and implementation come compiled once, from handcentric_catch_main
  # (tests/CMakeLists.txt).
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} handcentric_catch_main rapidcheck_catch)
  target_include_directories(${name} PRIVATE "${PROJECT_SOURCE_DIR}/tests/support")
  # Catch2's single header and RapidCheck's are most of each test file's compile time: parse
  # them once per executable.
  target_precompile_headers(${name} PRIVATE <catch2/catch.hpp> <rapidcheck.h> <Eigen/Core>)
  # With CMAKE_UNITY_BUILD (scripts/build.sh) the test files of one program compile together,
  # so their file-local helpers need distinct names.
  handcentric_warnings(${name})
  foreach(label IN LISTS ARG_LABELS)
    catch_discover_tests(${name} TEST_SPEC "[${label}]" PROPERTIES LABELS ${label})
  endforeach()
endfunction()

# handcentric_cli_test(<name> <exit code> <regex> <args separated by |>): runs the `handcentric`
# command and checks its exit code and that stdout + stderr match the regex
# (tests/support/expect_exit.cmake). Labelled `unit`.
function(handcentric_cli_test name code regex args)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} "-DCOMMAND=$<TARGET_FILE:handcentric>" "-DARGS=${args}"
                   "-DEXPECT_CODE=${code}" "-DEXPECT_REGEX=${regex}"
                   -P "${PROJECT_SOURCE_DIR}/tests/support/expect_exit.cmake")
  set_tests_properties(${name} PROPERTIES LABELS unit)
endfunction()
