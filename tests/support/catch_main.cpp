// Catch2 v2's main and implementation, compiled once (library handcentric_catch_main) for every
// test executable: each copy of it is most of a test folder's compile time, under a sanitizer
// more so. RapidCheck properties print their seed on failure; replay one with
// RC_PARAMS="seed=<seed>" (see docs/COMMANDS.md, "Tests and seeds").
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
