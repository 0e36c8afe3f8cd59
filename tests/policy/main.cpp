// Catch2 v2 main for the policy suite. RapidCheck properties print their seed on failure; replay
// one with RC_PARAMS="seed=<seed>" (see README.md).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
