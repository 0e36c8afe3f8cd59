# Runs COMMAND with ARGS ('|'-separated) and checks its exit code (EXPECT_CODE) and that its
# stdout + stderr match EXPECT_REGEX. Used by the command-line tests in CMakeLists.txt.
string(REPLACE "|" ";" arguments "${ARGS}")
execute_process(COMMAND "${COMMAND}" ${arguments} RESULT_VARIABLE code OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT "${code}" STREQUAL "${EXPECT_CODE}")
  message(FATAL_ERROR "exit code ${code}, expected ${EXPECT_CODE}\nstdout: ${out}\nstderr: ${err}")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT_REGEX}")
  message(FATAL_ERROR "output does not match '${EXPECT_REGEX}'\nstdout: ${out}\nstderr: ${err}")
endif()
