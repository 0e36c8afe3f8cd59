// Catch2 v2 main for the props suite. Checks carry their own seeds (CheckOptions::seed); the
// RapidCheck properties of catch.hpp replay with RC_PARAMS="seed=<seed>".
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
