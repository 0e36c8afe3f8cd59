// Catch2 v2 main for the proofs suite (every test case is tagged [proofs]).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
