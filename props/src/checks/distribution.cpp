#include "handcentric/props/checks/distribution.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace detail {

namespace {

// The columns `columns` of m.
Eigen::MatrixXd columns_of(const Eigen::MatrixXd& m, const std::vector<Eigen::Index>& columns) {
  Eigen::MatrixXd out(m.rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t c = 0; c < columns.size(); ++c)
    out.col(static_cast<Eigen::Index>(c)) = m.col(columns[c]);
  return out;
}

// The law of the coordinates `rows` of `law`.
GaussianLaw rows_of(const GaussianLaw& law, const std::vector<Eigen::Index>& rows) {
  GaussianLaw out;
  out.mean.resize(static_cast<Eigen::Index>(rows.size()));
  out.noise_map.resize(static_cast<Eigen::Index>(rows.size()), law.noise_map.cols());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    out.mean(static_cast<Eigen::Index>(r)) = law.mean(rows[r]);
    out.noise_map.row(static_cast<Eigen::Index>(r)) = law.noise_map.row(rows[r]);
  }
  return out;
}

// "0-2, 12-14 of 36": ascending indices as ranges.
std::string index_ranges(const std::vector<Eigen::Index>& indices, Eigen::Index width) {
  std::string out;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!out.empty()) out += ", ";
    out += std::to_string(indices[i]);
    if (j > i) {
      out += '-';
      out += std::to_string(indices[j]);
    }
    i = j + 1;
  }
  out += " of ";
  out += std::to_string(width);
  return out;
}

// Two Gaussian laws equal up to rounding: means within `tolerance`, covariances within
// `tolerance` times the larger covariance scale.
struct ExactComparison {
  LawDifference difference;
  double covariance_tolerance = 0.0;
  bool equal = false;
};
ExactComparison compare_exactly(const GaussianLaw& a, const GaussianLaw& b, double tolerance) {
  ExactComparison out;
  out.difference = law_difference(a, b);
  out.covariance_tolerance = tolerance * out.difference.covariance_scale;
  out.equal =
      out.difference.mean <= tolerance && out.difference.covariance <= out.covariance_tolerance;
  return out;
}

std::string describe(const ExactComparison& c, double tolerance) {
  return "means differ by " + format_number(c.difference.mean) + ", covariances by " +
         format_number(c.difference.covariance) + " (tolerance " + format_number(tolerance) +
         ", covariance " + format_number(c.covariance_tolerance) + ")";
}

// A case's coordinates as the exact comparison leaves them (compare_affine_part).
struct AffinePart {
  bool decided = false;  // every coordinate affine on both sides: the outcome is final
  bool split = false;    // the coordinates in `tested` go to the tests, the others were exact
  std::vector<Eigen::Index> tested;
  std::string exact_text;  // "; coordinates ... affine in eps, Gaussian laws: ..." when split
};

void set_exact_witness(CaseOutcome& outcome, const PartlyAffineLaw& law,
                       const PartlyAffineLaw& moved_law, const ExactComparison& exact,
                       double tolerance, std::string detail) {
  outcome.witness.before = law.law.mean;
  outcome.witness.after = moved_law.law.mean;
  outcome.witness.error = std::max(exact.difference.mean, exact.difference.covariance);
  outcome.witness.tolerance = tolerance;
  outcome.witness.detail = std::move(detail);
  outcome.holds = exact.equal;
}

// The exact half of a case: probes both sides' laws; when every coordinate is affine on both,
// decides the case (Gaussian laws), else compares the coordinates affine on both sides (the
// same ones) and leaves the others to the tests (a difference there decides the case too).
AffinePart compare_affine_part(const NoisePair& pair, double tolerance, const CheckOptions& options,
                               const DistributionOptions& distribution, CaseOutcome& outcome) {
  LawStatistics& statistics = outcome.statistics;
  AffinePart part;
  const std::optional<PartlyAffineLaw> law =
      partly_affine_law(pair.before, pair.noise_dimension, tolerance, options.noise_seed,
                        distribution.affinity_checks);
  // An output with no affine coordinate on one side has none to compare exactly: the other
  // side is not probed (a sampler through a network would cost n + 1 evaluations for nothing).
  const bool any_affine =
      law && std::any_of(law->affine.begin(), law->affine.end(), [](bool a) { return a; });
  const std::optional<PartlyAffineLaw> moved_law =
      law && (any_affine || law->affine.empty())
          ? partly_affine_law(pair.after, pair.noise_dimension, tolerance, options.noise_seed,
                              distribution.affinity_checks)
          : std::nullopt;
  if (law && moved_law && law->all_affine() && moved_law->all_affine()) {
    // Exact: two Gaussian laws are one iff their means and covariances agree.
    const ExactComparison exact = compare_exactly(law->law, moved_law->law, tolerance);
    set_exact_witness(outcome, *law, *moved_law, exact, tolerance,
                      "Gaussian laws (affine in eps): " + describe(exact, tolerance));
    part.decided = true;
    return part;
  }
  // Partly affine: the coordinates affine on both sides (the same ones) are compared exactly,
  // the others tested. Different affine coordinates on the two sides are a difference of the
  // laws too, but not one seen exactly: then every coordinate is tested.
  part.split = distribution.exact_affine_part && law && moved_law &&
               law->affine == moved_law->affine && any_affine;
  if (!part.split) {
    statistics.any_energy = true;
    return part;
  }
  std::vector<Eigen::Index> exact_coordinates;
  for (std::size_t j = 0; j < law->affine.size(); ++j)
    (law->affine[j] ? exact_coordinates : part.tested).push_back(static_cast<Eigen::Index>(j));
  const Eigen::Index width = law->law.mean.size();
  const ExactComparison exact = compare_exactly(
      rows_of(law->law, exact_coordinates), rows_of(moved_law->law, exact_coordinates), tolerance);
  statistics.any_partial = true;
  ++statistics.partial_cases;
  const std::string which = index_ranges(exact_coordinates, width);
  if (statistics.exact_coordinates.empty()) statistics.exact_coordinates = which;
  const std::string exact_text =
      "coordinates " + which + " affine in eps, Gaussian laws: " + describe(exact, tolerance);
  if (!exact.equal) {
    set_exact_witness(outcome, *law, *moved_law, exact, tolerance,
                      exact_text + "; the other coordinates were not tested");
    part.decided = true;
    return part;
  }
  part.exact_text = "; " + exact_text;
  return part;
}

Eigen::VectorXd draw_noise(Eigen::Index noise, std::mt19937_64& rng) {
  Eigen::VectorXd eps(noise);
  for (Eigen::Index j = 0; j < noise; ++j) eps(j) = standard_normal(rng);
  return eps;
}

// The draws with the same eps on both sides: x = before(eps_i), same_eps = after(eps_i), eps_i
// from mt19937_64(noise_seed), drawn in stretches (the first `samples`, or an extra case's
// paired draws, then the scale test's).
struct SharedDraws {
  const NoisePair& pair;
  std::mt19937_64 rng;
  Eigen::MatrixXd x, same_eps;

  // Rows [x.rows(), to) drawn, in the order of one generator whatever the steps.
  void draw_up_to(int to) {
    if (to > x.rows()) draw(static_cast<int>(x.rows()), to);
  }

  void draw(int from, int to) {
    std::vector<Eigen::VectorXd> drawn;
    for (int i = from; i < to; ++i) drawn.push_back(draw_noise(pair.noise_dimension, rng));
    ask_ahead([&] { return drawn; }, pair.before);
    ask_ahead([&] { return drawn; }, pair.after);
    for (int i = from; i < to; ++i) {
      const Eigen::VectorXd& eps = drawn[static_cast<std::size_t>(i - from)];
      const Eigen::VectorXd u = pair.before(eps);
      const Eigen::VectorXd v = pair.after(eps);
      if (i == 0) {
        x.resize(to, u.size());
        same_eps.resize(to, v.size());
      } else if (i == from) {
        x.conservativeResize(to, Eigen::NoChange);
        same_eps.conservativeResize(to, Eigen::NoChange);
      }
      if (u.size() != x.cols() || v.size() != same_eps.cols()) {
        throw InvalidArgument(pair.name + " changed length between noise draws");
      }
      x.row(i) = u.transpose();
      same_eps.row(i) = v.transpose();
    }
  }
};

// Both power computations bisect over many evaluations of the power: kept per thread, as every
// case of a check asks the same ones.
double remembered(std::tuple<Eigen::Index, double, double, int> key,
                  const std::function<double()>& compute) {
  thread_local std::map<std::tuple<Eigen::Index, double, double, int>, double> powers;
  const auto hit = powers.find(key);
  if (hit != powers.end()) return hit->second;
  const double value = compute();
  if (powers.size() > 4096) powers.clear();
  powers.emplace(key, value);
  return value;
}

// How a case's tests run: the level of each, the draws of the energy test (samples) and of the
// other two (draws: enough for the scale test to find scale_ratio with 90% power).
struct TestPlan {
  double level = 0.0;
  int samples = 0;
  int scale_permutations = 0;
  double scale_level = 0.0;
  int draws = 0;
};

TestPlan plan_tests(Eigen::Index dimension, double level, const DistributionOptions& distribution) {
  TestPlan plan;
  plan.level = level;
  plan.samples = distribution.samples;
  plan.scale_permutations = scale_test_permutations(level);
  plan.scale_level = permutation_level(level, plan.scale_permutations);
  plan.draws = plan.samples;
  if (distribution.scale_test && dimension > 0) {
    plan.draws = std::max(plan.samples,
                          static_cast<int>(remembered(
                              {dimension, plan.scale_level, distribution.scale_ratio, -1}, [&] {
                                return static_cast<double>(samples_for_scale_ratio(
                                    dimension, plan.scale_level, distribution.scale_ratio));
                              })));
  }
  return plan;
}

// The case's spread and, with the scale test, the sd ratio it finds with 90% power.
void record_spread(LawStatistics& statistics, const Eigen::MatrixXd& x_tested, const TestPlan& plan,
                   const DistributionOptions& distribution) {
  const Eigen::Index dimension = x_tested.cols();
  statistics.largest_dimension = std::max(statistics.largest_dimension, dimension);
  if (dimension == 0) return;
  const Eigen::RowVectorXd mean = x_tested.colwise().mean();
  const double variance = (x_tested.rowwise() - mean).squaredNorm() /
                          (static_cast<double>(plan.samples - 1) * static_cast<double>(dimension));
  statistics.largest_spread = std::max(statistics.largest_spread, std::sqrt(variance));
  if (distribution.scale_test) {
    statistics.largest_scale_ratio =
        std::max(statistics.largest_scale_ratio,
                 remembered({dimension, plan.scale_level, 0.0, plan.draws}, [&] {
                   return scale_test_detectable_ratio(dimension, plan.draws, plan.scale_level);
                 }));
  }
}

// The three tests of a case that is not pointwise, each at a third of the case's level:
//  - the energy test (a permutation test: exact level, little power against a mean shift in
//    many dimensions) on the first `samples` draws of before(eps) and after(eps') (independent
//    draws: a permutation test needs exchangeable samples; shared draws would not be);
//  - the paired test of the mean difference on the shared draws (equal laws have equal means,
//    so E[before - after] = 0: Student's t per coordinate, Bonferroni; its level is
//    asymptotic, and a mean that moves by a constant, as when a policy mixes frames, stands
//    out at once);
//  - the scale test on all draws of before(eps) and after(eps') (a permutation test: exact
//    level; it finds a covariance turned or stretched with the mean kept, which the other two
//    see only when it is large).
void run_tests(const NoisePair& pair, const SharedDraws& shared,
               const std::vector<Eigen::Index>& tested, const TestPlan& plan, double tolerance,
               const CheckOptions& options, const DistributionOptions& distribution,
               const std::string& exact_text, CaseOutcome& outcome) {
  // The shared draws: plan.draws, or more at an extra case (for the paired test alone).
  const Eigen::MatrixXd shared_before = columns_of(shared.x, tested);
  const Eigen::MatrixXd shared_after = columns_of(shared.same_eps, tested);
  const std::string shared_text =
      shared_before.rows() > plan.draws
          ? " (" + std::to_string(shared_before.rows()) + " shared draws)"
          : std::string();
  const std::string levels_text = " (" + std::to_string(plan.draws) + " draws; each at level " +
                                  format_number(plan.level) + ")" + exact_text;
  // A case holds when all three tests do, so the first failing one decides it: the cheap paired
  // test first (no permutations, no fresh draws), then the energy test, then the scale test.
  // The verdict, the shrunk witness and the policy's answers up to that test are the ones all
  // three would give; a failing case only skips the permutations (most of the cost of a failing
  // check, whose shrinking decides some twenty failing cases) and the fresh draws it no longer
  // needs.
  const double paired = paired_mean_test(shared_before - shared_after, tolerance);
  if (paired < plan.level) {
    // Both samples of the witness come from the shared draws (each row a draw of its own law).
    outcome.witness.after = shared.same_eps.row(0).transpose();
    outcome.witness.error =
        energy_distance(shared_before.topRows(plan.samples), shared_after.topRows(plan.samples));
    outcome.witness.p_value = std::min(1.0, 3.0 * paired);
    outcome.witness.detail = "paired mean test p = " + format_number(paired) + shared_text +
                             ", below its level: the energy and scale tests were not run" +
                             levels_text;
    outcome.holds = false;
    return;
  }
  std::mt19937_64 fresh(options.noise_seed ^ 0x9e3779b97f4a7c15ULL);
  Eigen::MatrixXd y(plan.draws, shared.same_eps.cols());
  std::vector<Eigen::VectorXd> fresh_draws;
  for (int i = 0; i < plan.draws; ++i)
    fresh_draws.push_back(draw_noise(pair.noise_dimension, fresh));
  ask_ahead([&] { return fresh_draws; }, pair.after);
  for (int i = 0; i < plan.draws; ++i)
    y.row(i) = pair.after(fresh_draws[static_cast<std::size_t>(i)]).transpose();
  const Eigen::MatrixXd before = shared_before.topRows(plan.draws), after = columns_of(y, tested);
  const TwoSampleResult test =
      energy_test(before.topRows(plan.samples), after.topRows(plan.samples),
                  permutations_for(plan.level), options.seed, plan.level);
  outcome.witness.after = y.row(0).transpose();
  outcome.witness.error = test.energy_distance;
  std::string detail =
      "energy test p = " + format_number(test.p_value) + " (" + std::to_string(plan.samples) +
      " draws), paired mean test p = " + format_number(paired) + shared_text + ", ";
  ScaleTestResult scale;
  if (test.p_value < plan.level) {
    detail += "below its level: the scale test was not run";
  } else if (distribution.scale_test) {
    scale = scale_test(before, after, plan.scale_permutations, options.seed ^ 0x5ca1e5ca1e5ca1e5ULL,
                       plan.level, tolerance);
    detail += "scale test p = " + format_number(scale.p_value) +
              (scale.coordinate >= 0
                   ? " (coordinate " +
                         std::to_string(tested[static_cast<std::size_t>(scale.coordinate)]) +
                         ", sd ratio " + format_number(scale.sd_ratio) + ")"
                   : "");
  } else {
    detail += "no scale test";
  }
  outcome.witness.p_value = std::min(1.0, 3.0 * std::min({test.p_value, paired, scale.p_value}));
  outcome.witness.detail = detail + levels_text;
  outcome.holds = test.p_value >= plan.level && paired >= plan.level && scale.p_value >= plan.level;
}

}  // namespace

void merge(LawStatistics& into, const LawStatistics& one) {
  into.any_energy = into.any_energy || one.any_energy;
  into.any_partial = into.any_partial || one.any_partial;
  into.partial_cases += one.partial_cases;
  if (into.exact_coordinates.empty()) into.exact_coordinates = one.exact_coordinates;
  into.largest_dimension = std::max(into.largest_dimension, one.largest_dimension);
  into.largest_spread = std::max(into.largest_spread, one.largest_spread);
  into.largest_scale_ratio = std::max(into.largest_scale_ratio, one.largest_scale_ratio);
}

CaseOutcome compare_laws(const NoisePair& pair, double tolerance, const CheckOptions& options,
                         const DistributionOptions& distribution, int paired_draws) {
  const double alpha = distribution.family_alpha / distribution.cases;  // Bonferroni
  const double level = alpha / 3.0;                                     // each of the three tests
  CaseOutcome outcome;
  AffinePart part = compare_affine_part(pair, tolerance, options, distribution, outcome);
  if (part.decided) return outcome;
  SharedDraws shared{pair, std::mt19937_64(options.noise_seed), {}, {}};
  const Eigen::MatrixXd &x = shared.x, &same_eps = shared.same_eps;
  // An extra case takes all its shared draws first: the two laws may agree on the first
  // `samples` draws and differ on rarer ones, which are what the extra draws are for.
  shared.draw_up_to(std::max(distribution.samples, paired_draws));
  if (!part.split) {
    part.tested.resize(static_cast<std::size_t>(x.cols()));
    std::iota(part.tested.begin(), part.tested.end(), Eigen::Index{0});
  }
  outcome.witness.before = x.row(0).transpose();
  outcome.witness.tolerance = alpha;
  if (x.cols() != same_eps.cols()) {  // different lengths: different laws
    outcome.witness.after = same_eps.row(0).transpose();
    outcome.witness.error = std::numeric_limits<double>::infinity();
    outcome.witness.p_value = 0.0;
    outcome.holds = false;
    return outcome;
  }
  const std::vector<Eigen::Index>& tested = part.tested;
  const auto dimension = static_cast<Eigen::Index>(tested.size());
  const TestPlan plan = plan_tests(dimension, level, distribution);
  const Eigen::MatrixXd x_tested = columns_of(x, tested);
  record_spread(outcome.statistics, x_tested.topRows(plan.samples), plan, distribution);
  const double pointwise =
      dimension > 0 ? (x_tested - columns_of(same_eps, tested)).lpNorm<Eigen::Infinity>() : 0.0;
  if (pointwise <= tolerance) {
    // The same value on every shared draw: the two distributions are the same one, no test needed.
    outcome.witness.after = same_eps.row(0).transpose();
    outcome.witness.error =
        dimension > 0 ? energy_distance(x_tested.topRows(plan.samples),
                                        columns_of(same_eps, tested).topRows(plan.samples))
                      : 0.0;
    outcome.witness.p_value = 1.0;
    return outcome;
  }
  // Not pointwise: more shared draws if the scale test needs them, as many independent ones, and
  // the three tests.
  shared.draw_up_to(plan.draws);
  run_tests(pair, shared, tested, plan, tolerance, options, distribution, part.exact_text, outcome);
  return outcome;
}

void finish_distribution_verdict(Verdict& verdict, const LawStatistics& statistics,
                                 const DistributionOptions& distribution) {
  verdict.method = statistics.any_energy    ? Method::energy_test
                   : statistics.any_partial ? Method::partly_exact
                                            : Method::exact_gaussian;
  if (verdict.method == Method::exact_gaussian || !verdict.invariant) return;
  if (statistics.largest_dimension > 0) {
    verdict.detectable_shift =
        energy_test_detectable_shift(statistics.largest_dimension, distribution.samples,
                                     distribution.family_alpha / distribution.cases / 3.0) *
        statistics.largest_spread;
  }
  if (statistics.largest_scale_ratio > 0.0)
    verdict.detectable_scale_ratio = statistics.largest_scale_ratio;
  if (statistics.any_partial && verdict.note.empty()) {
    verdict.note = "on " + std::to_string(statistics.partial_cases) +
                   " case(s) the coordinates affine in the noise on both sides (e.g. " +
                   statistics.exact_coordinates +
                   ") were compared exactly as Gaussian laws, the others by the tests";
  }
}

void require_distribution_options(const DistributionOptions& distribution) {
  if (distribution.cases < 1 || distribution.samples < 2 ||
      distribution.extra_case_paired_draws < 0 ||
      !(distribution.family_alpha > 0.0 && distribution.family_alpha < 1.0) ||
      distribution.affinity_checks < 1 ||
      (distribution.scale_test &&
       !(distribution.scale_ratio > 1.0 && std::isfinite(distribution.scale_ratio)))) {
    throw InvalidArgument(
        "distribution options need cases >= 1, samples >= 2, extra_case_paired_draws >= 0, 0 < "
        "alpha < 1, affinity_checks >= 1 and a scale ratio > 1, got cases " +
        std::to_string(distribution.cases) + ", samples " + std::to_string(distribution.samples) +
        ", extra_case_paired_draws " + std::to_string(distribution.extra_case_paired_draws) +
        ", alpha " + format_number(distribution.family_alpha) + ", affinity_checks " +
        std::to_string(distribution.affinity_checks) + ", scale ratio " +
        format_number(distribution.scale_ratio));
  }
}

Verdict run_distribution_check(const PairOfCase& pair_of, Component component, Group group,
                               const CheckOptions& options,
                               const DistributionOptions& distribution) {
  // A drawn case, or (paired_draws = extra_case_paired_draws) an extra one.
  auto case_with = [&](int paired_draws) {
    return [&, paired_draws](const Scene& scene, const RigidTransform& g) {
      const Scene moved = g * scene;
      CaseOutcome outcome = compare_laws(
          pair_of(scene, moved, g), pointwise_tolerance(scene, moved, options.relative_tolerance),
          options, distribution, paired_draws);
      outcome.witness.scene = scene;
      outcome.witness.g = g;
      return outcome;
    };
  };
  LawStatistics statistics;
  Verdict verdict = run_check(case_with(0), component, group, Mode::distribution, options,
                              distribution.cases, distribution.shrink_budget, &statistics,
                              case_with(distribution.extra_case_paired_draws));
  finish_distribution_verdict(verdict, statistics, distribution);
  return verdict;
}

}  // namespace detail

Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                                      Group group, const CheckOptions& options,
                                      const DistributionOptions& distribution) {
  if (!target) throw InvalidArgument("check_distribution_invariance needs a flow target, got null");
  if (component != Component::flow_input && component != Component::flow_target) {
    throw InvalidArgument("in-distribution checks are about flow_input or flow_target, got " +
                          to_string(component));
  }
  detail::require_distribution_options(distribution);
  auto pair_of = [&](const Scene& scene, const Scene& moved, const RigidTransform&) {
    auto part_of = [&](const Scene& s) {
      return [&target, &options, component, s](const Eigen::VectorXd& eps) -> Eigen::VectorXd {
        const FlowSample sample = (*target)(s, eps, options.flow_time);
        return component == Component::flow_input ? sample.input : sample.target;
      };
    };
    return detail::NoisePair{part_of(scene), part_of(moved), target->noise_dimension(scene),
                             target->name() + ": the " + to_string(component)};
  };
  return detail::run_distribution_check(pair_of, component, group, options, distribution);
}

}  // namespace handcentric::props
