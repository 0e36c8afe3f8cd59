#include "handcentric/props/run.hpp"

#include <cstdlib>
#include <cstring>

namespace handcentric::props {

rc::detail::TestParams test_params() {
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  const char* rc_params = std::getenv("RC_PARAMS");
  if (rc_params == nullptr || std::strstr(rc_params, "seed=") == nullptr) params.seed = kDefaultSeed;
  if (rc_params == nullptr || std::strstr(rc_params, "max_success=") == nullptr) {
    params.maxSuccess = kDefaultCases;
  }
  return params;
}

}  // namespace handcentric::props
