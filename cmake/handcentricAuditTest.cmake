# handcentric_add_audit_test: a ctest gate on an equivariance claim, for another project's CI.
#
#   handcentric_add_audit_test(NAME my_repr COMMAND /usr/bin/python3 rep.py EXPECT se3)
#   handcentric_add_audit_test(NAME my_policy POLICY_COMMAND /usr/bin/python3 policy.py
#                              EXPECT se3 c8)
#   handcentric_add_audit_test(NAME relative_is_not_rotation_invariant REPR relative
#                              EXPECT actions:rotation WILL_FAIL)
#
# Runs `handcentric audit` on a representation plug-in (COMMAND, --exec), a policy plug-in
# (POLICY_COMMAND, --policy-exec) or a built-in (REPR) with `--expect` the EXPECT items
# (GROUP, or COMPONENT:GROUP); the test fails, and prints the shrunk witness, when an expected
# invariance or equivariance does not hold. ARGS adds audit options (e.g. --precision float32
# --cases 200). WILL_FAIL registers a claim that must be refuted.
# HANDCENTRIC_EXECUTABLE names the `handcentric` program (set by find_package(handcentric)).
function(handcentric_add_audit_test)
  cmake_parse_arguments(AUDIT "WILL_FAIL" "NAME;REPR" "COMMAND;POLICY_COMMAND;EXPECT;ARGS" ${ARGN})
  if(NOT AUDIT_NAME OR NOT AUDIT_EXPECT)
    message(FATAL_ERROR "handcentric_add_audit_test needs NAME and EXPECT, e.g. "
                        "handcentric_add_audit_test(NAME my_repr COMMAND python3 rep.py "
                        "EXPECT se3)")
  endif()
  if(AUDIT_COMMAND)
    list(JOIN AUDIT_COMMAND " " command)
    set(subject --exec "${command}")
  elseif(AUDIT_POLICY_COMMAND)
    list(JOIN AUDIT_POLICY_COMMAND " " command)
    set(subject --policy-exec "${command}")
  elseif(AUDIT_REPR)
    set(subject --repr "${AUDIT_REPR}")
  else()
    message(FATAL_ERROR "handcentric_add_audit_test(${AUDIT_NAME}): "
                        "give COMMAND, POLICY_COMMAND or REPR")
  endif()
  list(JOIN AUDIT_EXPECT "," expect)
  add_test(NAME ${AUDIT_NAME}
           COMMAND "${HANDCENTRIC_EXECUTABLE}" audit ${subject} --expect "${expect}" ${AUDIT_ARGS})
  if(AUDIT_WILL_FAIL)
    set_tests_properties(${AUDIT_NAME} PROPERTIES WILL_FAIL TRUE)
  endif()
endfunction()
