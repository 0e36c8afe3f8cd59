#pragma once
// CHECK that `expr` throws `Type` and that its message matches a Catch2 string matcher.
#include <catch2/catch.hpp>

#define HC_CHECK_THROWS(expr, Type, matcher) \
  do {                                       \
    CHECK_THROWS_AS(expr, Type);             \
    CHECK_THROWS_WITH(expr, matcher);        \
  } while (false)
