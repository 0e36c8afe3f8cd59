// The rotation generators: Haar-distributed (the angle's law, the axis, E[R] = 0), and a failure
// shrinks toward the identity, to the smallest angle that still fails; a uniform angle (not
// Haar), Shoemake's map and an angle drawn up from -pi (both shrink to a half turn) are the
// planted faults.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "handcentric/core/sampling.hpp"
#include "handcentric/props/observation/generators.hpp"

using namespace handcentric;

namespace {

constexpr double kHalfTurn = std::numbers::pi;  // rad
constexpr int kDraws = 4000;
// Kolmogorov's distribution exceeds 1.95 with probability 0.001: the KS statistic of kDraws
// samples of the right law stays below 1.95 / sqrt(kDraws) but one time in a thousand.
const double kCriticalKs = 1.95 / std::sqrt(static_cast<double>(kDraws));

// The Kolmogorov-Smirnov statistic of `samples` against the continuous CDF `cdf`.
template <typename Cdf>
double ks_statistic(std::vector<double> samples, Cdf cdf) {
  std::sort(samples.begin(), samples.end());
  const double n = static_cast<double>(samples.size());
  double d = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double f = cdf(samples[i]);
    d = std::max({d, (static_cast<double>(i) + 1.0) / n - f, f - static_cast<double>(i) / n});
  }
  return d;
}

struct HaarDefects {
  double angle_ks = 0.0;    ///< the angle against F(t) = (t - sin t) / pi
  double axis_ks = 0.0;     ///< the axis's z against uniform on [-1, 1] (Archimedes)
  double mean_entry = 0.0;  ///< the largest |entry| of the mean of R (0 for Haar)
};

// kDraws rotations of `gen`, seeded, and how far they are from Haar's law. Drawn at RapidCheck's
// nominal size, where its integers span their whole range (a property's first cases come at
// smaller sizes, which narrow the range toward where it shrinks to).
HaarDefects haar_defects(const rc::Gen<Rotation>& gen) {
  rc::Random random(rc::Random::Key{{5, 6, 7, 8}});
  std::vector<double> angles, axis_z;
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (int i = 0; i < kDraws; ++i) {
    const Rotation R = gen(random.split(), rc::kNominalSize).value();
    const Eigen::Vector3d r = R.log();
    angles.push_back(R.angle());
    if (r.norm() > 0.0) axis_z.push_back(r.z() / r.norm());
    sum += R.matrix();
  }
  HaarDefects d;
  d.angle_ks = ks_statistic(angles, [](double t) { return (t - std::sin(t)) / kHalfTurn; });
  d.axis_ks = ks_statistic(axis_z, [](double z) { return 0.5 * (z + 1.0); });
  d.mean_entry = (sum / kDraws).cwiseAbs().maxCoeff();
  return d;
}

// Each entry of a Haar rotation has mean 0 and variance 1/3: 4.5 standard errors of the mean
// bound all nine entries' means but about one time in 10^4.
const double kMeanEntryBound = 4.5 * std::sqrt(1.0 / 3.0 / kDraws);

// Planted fault: a uniform axis and an angle uniform on [0, pi) (too many small angles).
rc::Gen<Rotation> uniform_angle_rotation() {
  return rc::gen::map(
      rc::gen::tuple(rc::gen::inRange(0, 1 << 30), rc::gen::inRange(0, 1 << 30),
                     rc::gen::inRange(0, 1 << 30)),
      [](const auto& k) {
        const double scale = 1.0 / (1 << 30);
        return Rotation::exp(kHalfTurn * std::get<2>(k) * scale *
                             sphere_point(std::get<0>(k) * scale, std::get<1>(k) * scale));
      });
}

// Planted fault: Shoemake's map of three uniform numbers, Haar too, but its numbers shrink to 0
// and map there to the quaternion (0, 0, 1, 0), a half turn about y.
rc::Gen<Rotation> shoemake_generator() {
  return rc::gen::map(rc::gen::tuple(rc::gen::inRange(0, 1 << 30), rc::gen::inRange(0, 1 << 30),
                                     rc::gen::inRange(0, 1 << 30)),
                      [](const auto& k) {
                        const double scale = 1.0 / (1 << 30);
                        return shoemake_rotation(std::get<0>(k) * scale, std::get<1>(k) * scale,
                                                 std::get<2>(k) * scale);
                      });
}

// What RapidCheck does with a failing case: take the first shrink that still fails, until none
// does. Starts from the first of `gen`'s seeded draws that fails.
template <typename T, typename Fails>
T shrunk_failure(const rc::Gen<T>& gen, Fails fails) {
  rc::Random random(rc::Random::Key{{9, 10, 11, 12}});
  rc::Shrinkable<T> failing = gen(random.split(), rc::kNominalSize);
  while (!fails(failing.value())) failing = gen(random.split(), rc::kNominalSize);
  for (bool shrunk = true; shrunk;) {
    shrunk = false;
    auto shrinks = failing.shrinks();
    for (auto next = shrinks.next(); next; next = shrinks.next()) {
      if (fails(next->value())) {
        failing = *next;
        shrunk = true;
        break;
      }
    }
  }
  return failing.value();
}

// The rotation of se2's elements (a turn about z mixed with its edge cases, 0 to pi).
rc::Gen<Rotation> se2_rotation() {
  return rc::gen::map(props::group_element(props::Group::se2),
                      [](const RigidTransform& g) { return g.rotation(); });
}

// Planted fault: a turn about z whose angle is drawn from [-pi, pi] as an integer from the low
// end of its range up, which RapidCheck shrinks toward -pi.
rc::Gen<Rotation> turn_from_minus_pi() {
  return rc::gen::map(rc::gen::inRange(-(1 << 30), (1 << 30) + 1),
                      [](int k) { return Rotation::about_z(kHalfTurn * k / (1 << 30)); });
}

// A map that breaks for every rotation beyond 0.1 rad.
bool beyond_a_tenth(const Rotation& R) {
  return R.angle() > 0.1;
}

}  // namespace

TEST_CASE("haar_angle_inverts_the_cdf_of_the_haar_angle_to_double_precision", "[unit]") {
  CHECK(haar_angle(0.0) == 0.0);
  CHECK(haar_angle(1.0) == kHalfTurn);
  double previous = 0.0;
  for (const double u :
       {0x1p-30, 0x1p-29, 1e-6, 1e-3, 0.1, 0.25, 0.5, 0.75, 0.9, 0.999, 1.0 - 0x1p-30}) {
    const long double t = haar_angle(u);
    // Long double's t - sin t still cancels at small t; 1e-12 of u is well above that.
    const long double cdf = (t - std::sin(t)) / std::numbers::pi_v<long double>;
    CHECK(std::abs(cdf - u) <= 1e-12L * u);
    CHECK(static_cast<double>(t) > previous);
    previous = static_cast<double>(t);
  }
  // Small u: t^3 / 6 = pi u to leading order.
  CHECK(haar_angle(0x1p-30) == Approx(std::cbrt(6.0 * kHalfTurn * 0x1p-30)).epsilon(1e-6));
}

TEST_CASE("haar_rotations_have_the_haar_angle_law_a_uniform_axis_and_mean_zero", "[property]") {
  for (const auto& [name, gen] : {std::pair{"haar_rotation", props::haar_rotation()},
                                  std::pair{"shoemake", shoemake_generator()}}) {
    const HaarDefects d = haar_defects(gen);
    INFO(name << ": angle KS " << d.angle_ks << ", axis KS " << d.axis_ks << ", mean entry "
              << d.mean_entry);
    CHECK(d.angle_ks < kCriticalKs);
    CHECK(d.axis_ks < kCriticalKs);
    CHECK(d.mean_entry < kMeanEntryBound);
  }
}

TEST_CASE("mutant_a_uniform_angle_fails_the_haar_test", "[property]") {
  const HaarDefects d = haar_defects(uniform_angle_rotation());
  INFO("angle KS " << d.angle_ks << ", mean entry " << d.mean_entry);
  CHECK(d.angle_ks > kCriticalKs);
  CHECK(d.mean_entry > kMeanEntryBound);  // E[R] = I / 3 for a uniform angle
}

TEST_CASE("a_rotation_that_fails_beyond_a_tenth_of_a_radian_shrinks_to_just_past_it",
          "[property]") {
  for (const auto& [name, gen] :
       {std::pair{"haar_rotation", props::haar_rotation()},
        std::pair{"rotation", props::rotation()}, std::pair{"se2", se2_rotation()}}) {
    const Rotation R = shrunk_failure(gen, beyond_a_tenth);
    INFO(name << ": shrunk to angle " << R.angle());
    CHECK(R.angle() > 0.1);
    CHECK(R.angle() < 0.1001);
  }
}

TEST_CASE("mutant_shoemake_and_low_end_angles_shrink_to_a_half_turn", "[property]") {
  for (const auto& [name, gen] : {std::pair{"shoemake", shoemake_generator()},
                                  std::pair{"turn_from_minus_pi", turn_from_minus_pi()}}) {
    const Rotation R = shrunk_failure(gen, beyond_a_tenth);
    INFO(name << ": shrunk to angle " << R.angle());
    CHECK(R.angle() > 3.14);
  }
}
