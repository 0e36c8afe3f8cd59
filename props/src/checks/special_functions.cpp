#include "special_functions.hpp"

#include <boost/math/distributions/complement.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/policies/policy.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/statistics.hpp"

namespace handcentric::props {
namespace {

namespace policies = boost::math::policies;

// special_functions.hpp says why: every error throws, underflow gives 0.
using Policy = policies::policy<policies::domain_error<policies::throw_on_error>,
                                policies::pole_error<policies::throw_on_error>,
                                policies::overflow_error<policies::throw_on_error>,
                                policies::evaluation_error<policies::throw_on_error>,
                                policies::rounding_error<policies::throw_on_error>,
                                policies::indeterminate_result_error<policies::throw_on_error>,
                                policies::underflow_error<policies::ignore_error>,
                                policies::denorm_error<policies::ignore_error>>;
using Normal = boost::math::normal_distribution<double, Policy>;
using StudentsT = boost::math::students_t_distribution<double, Policy>;

// f(), with what Boost.Math throws as handcentric's errors. A domain or pole error
// (std::domain_error) is a bad argument; overflow (std::overflow_error), an evaluation that did
// not converge (boost::math::evaluation_error) and a rounding error (boost::math::rounding_error)
// derive from std::runtime_error.
template <class F>
double evaluate(const char* what, const F& f) {
  try {
    return f();
  } catch (const std::domain_error& e) {
    throw InvalidArgument(std::string(what) + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
}

}  // namespace

double student_t_two_sided_p(double t, double degrees_of_freedom) {
  if (!(degrees_of_freedom > 0.0))
    throw InvalidArgument("Student's t needs positive degrees of freedom");
  if (!std::isfinite(t)) return std::isnan(t) ? 1.0 : 0.0;
  return evaluate("student_t_two_sided_p", [&] {
    // P(|T| > |t|) = 2 P(T < -|t|): the lower tail, with no cancellation for large |t|.
    return 2.0 * boost::math::cdf(StudentsT(degrees_of_freedom), -std::abs(t));
  });
}

namespace detail {

double normal_upper_tail(double z) {
  return evaluate("normal_upper_tail",
                  [&] { return boost::math::cdf(boost::math::complement(Normal(), z)); });
}

double normal_upper_quantile(double p) {
  return evaluate("normal_upper_quantile",
                  [&] { return boost::math::quantile(boost::math::complement(Normal(), p)); });
}

}  // namespace detail
}  // namespace handcentric::props
