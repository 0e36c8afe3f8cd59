#include "handcentric/props/injectivity.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/generators.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace {

// Chunks closer than this (m or rad, per pose) are not "different": far above any rounding, far
// below a real change of plan, so a float32 encoder does not collide by rounding.
constexpr double kSmallestChange = 1e-3;

enum class Change { one_translation, one_rotation, whole_chunk, other_chunk };

// A vector with norm in [kSmallestChange, ~1.7]: `v`, lengthened when it is shorter.
Eigen::Vector3d at_least_smallest(Eigen::Vector3d v) {
  const double norm = v.norm();
  if (norm < kSmallestChange)
    return norm == 0.0 ? Eigen::Vector3d(kSmallestChange, 0, 0) : v * (kSmallestChange / norm);
  return v;
}

// The second chunk of a pair: `first`'s chunk changed as `change` says.
std::vector<RigidTransform> changed_chunk(const Scene& first, Change change, int index,
                                          const Eigen::Vector3d& v, const Eigen::Vector3d& w,
                                          const Rotation& R) {
  std::vector<RigidTransform> chunk = first.world_T_hand_chunk;
  const std::size_t k = static_cast<std::size_t>(index) % chunk.size();
  switch (change) {
    case Change::one_translation:
      chunk[k] = RigidTransform(chunk[k].rotation(), chunk[k].translation() + at_least_smallest(v));
      break;
    case Change::one_rotation:
      chunk[k] =
          chunk[k] * RigidTransform(Rotation::exp(at_least_smallest(w)), Eigen::Vector3d::Zero());
      break;
    case Change::whole_chunk: {
      const RigidTransform h(R, at_least_smallest(v));
      for (RigidTransform& T : chunk) T = h * T;
      break;
    }
    case Change::other_chunk: {
      // Another smooth chunk from T_0: a constant body twist per step.
      Twist twist;
      twist << 0.1 * v, 0.3 * w;
      const RigidTransform step = RigidTransform::exp(twist);
      RigidTransform world_T_handk = first.world_T_hand0();
      for (RigidTransform& T : chunk) T = world_T_handk = world_T_handk * step;
      break;
    }
  }
  return chunk;
}

using detail::chunk_distance;
using detail::inf_distance;

}  // namespace

Injectivity check_injectivity(std::shared_ptr<const Representation> representation,
                              const CheckOptions& options) {
  if (!representation) throw InvalidArgument("check_injectivity needs a representation, got null");
  if (options.cases < 1)
    throw InvalidArgument("check_injectivity needs at least 1 case, got " +
                          std::to_string(options.cases));
  Injectivity result;
  const bool decodes = representation->can_decode();
  bool searching = true;
  int shrink_evaluations = 0;
  std::exception_ptr error;
  const SceneShape shape = options.shape;
  const double relative = options.relative_tolerance;
  auto property = [&] {
    if (error) return;
    if (!searching && ++shrink_evaluations > (options.shrink ? 1000 : 0)) return;
    const Scene first = *scene(shape);
    const auto change = static_cast<Change>(*rc::gen::inRange(0, 4));
    const int index = *rc::gen::inRange(0, 64);
    const Eigen::Vector3d v = *translation(1.0), w = *translation(1.0);
    const Rotation R = *rotation();
    Scene second = first;
    second.world_T_hand_chunk = changed_chunk(first, change, index, v, w, R);
    try {
      const Eigen::VectorXd a = representation->encode_actions(first);
      if (searching && decodes && !result.round_trip_failure) {
        const std::vector<RigidTransform> decoded = representation->decode_in_scene(a, first);
        const double round_trip = chunk_distance(decoded, first.world_T_hand_chunk);
        const double tolerance = pointwise_tolerance(first, first, relative);
        ++result.round_trips;
        if (!(round_trip <= tolerance))
          result.round_trip_failure = RoundTripFailure{first, decoded, round_trip, tolerance};
      }
      const double apart = chunk_distance(first.world_T_hand_chunk, second.world_T_hand_chunk);
      const double scale = 1.0 + std::max(length_scale(first), length_scale(second));
      if (apart < 1e-6 * scale) return;  // the change did nothing measurable: not a pair
      const Eigen::VectorXd b = representation->encode_actions(second);
      if (searching) ++result.cases;
      const double tolerance = pointwise_tolerance(first, second, relative);
      const double action_distance = inf_distance(a, b);
      if (action_distance <= tolerance) {
        searching = false;
        result.collision = Collision{first, second, a, b, apart, action_distance, tolerance};
        RC_FAIL("two chunks, one action vector");
      }
    } catch (const Error&) {
      error = std::current_exception();
    }
  };
  detail::run_silently(property, "injectivity of " + representation->name(), options.seed,
                       options.cases);
  if (error) std::rethrow_exception(error);
  if (result.collision) {
    result.injective = false;
    result.how = "two different chunks (apart by " +
                 format_number(result.collision->chunk_distance) +
                 ") with the same observation map to one action vector: the map loses information";
  } else if (decodes && !result.round_trip_failure && result.round_trips > 0) {
    result.injective = true;
    result.how = "decode(encode(s)) gave back the chunk on all " +
                 std::to_string(result.round_trips) + " scenes, and no two of " +
                 std::to_string(result.cases) + " chunk pairs collided";
  } else {
    result.how = "no two of " + std::to_string(result.cases) + " chunk pairs collided, but " +
                 (decodes ? "decode(encode(s)) did not give back the chunk (see round_trip_failure)"
                          : "without a decoder that cannot prove the map injective");
  }
  return result;
}

std::string format_collision(const Collision& collision) {
  std::ostringstream out;
  const Scene& s = collision.first;
  out << "same observation: H = " << s.history_length() << ", " << s.hand_points.size()
      << " eye-in-hand and " << s.world_points.size() << " world points\n";
  for (std::size_t k = 0; k < s.world_T_hand_chunk.size(); ++k) {
    const RigidTransform& a = s.world_T_hand_chunk[k];
    const RigidTransform& b = collision.second.world_T_hand_chunk[k];
    if (distance(a, b) == 0.0) continue;
    out << "  T_" << k + 1 << ": r = " << format_matrix(a.rotation().log())
        << ", p = " << format_matrix(a.translation())
        << "\n   vs   r = " << format_matrix(b.rotation().log())
        << ", p = " << format_matrix(b.translation()) << "\n";
  }
  out << "both encode to "
      << format_matrix(collision.actions_first.head(
             std::min<Eigen::Index>(12, collision.actions_first.size())))
      << (collision.actions_first.size() > 12 ? " ..." : "") << "\n"
      << "actions differ by " << format_number(collision.action_distance) << " <= tolerance "
      << format_number(collision.tolerance) << "; chunks differ by "
      << format_number(collision.chunk_distance);
  return out.str();
}

}  // namespace handcentric::props
