#include "handcentric/props/checks/injectivity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace {

// The pairs search changes a chunk by at least this (m or rad, per pose): it looks for gross
// losses, far above rounding. Smaller changes are the resolution scan's.
constexpr double kSmallestChange = 1e-3;

// A pair is tried only when its change exceeds this many tolerances: a map in the chunk's units
// moves its actions by at least 1/sqrt(3) of a change (one coordinate of a translation), so
// smaller changes may collide in any map, however faithful.
constexpr double kPairMargin = 4.0;

// A colliding resolution pair is retried at sizes this much larger (10^(1/8)) while it collides:
// a tokenizer's bin is then found within 33 %, not within the decade the pair was drawn in.
constexpr double kGrowth = 1.333521432163324;

enum class Change { one_translation, one_rotation, whole_chunk, other_chunk };

const char* describe(Change change) {
  switch (change) {
    case Change::one_translation:
      return "one pose's translation moved";
    case Change::one_rotation:
      return "one pose's rotation turned";
    case Change::whole_chunk:
      return "the whole chunk moved by a rigid motion";
    case Change::other_chunk:
      break;
  }
  return "another chunk drawn";
}

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

// The resolution scan's changes of a given size: translations in m, rotations in rad.
enum class ScanChange { one_translation, whole_translation, one_rotation, whole_rotation };
constexpr int kScanChanges = 4;

bool in_metres(ScanChange change) {
  return change == ScanChange::one_translation || change == ScanChange::whole_translation;
}

// `chunk` with pose k (or every pose) moved by `size` along the unit vector u, or turned by
// `size` about u: pose k in its own frame, the whole chunk rigidly about its first position.
std::vector<RigidTransform> scaled_change(std::vector<RigidTransform> chunk, ScanChange change,
                                          std::size_t k, const Eigen::Vector3d& u, double size) {
  switch (change) {
    case ScanChange::one_translation:
      chunk[k] = RigidTransform(chunk[k].rotation(), chunk[k].translation() + size * u);
      break;
    case ScanChange::whole_translation:
      for (RigidTransform& T : chunk) T = RigidTransform(T.rotation(), T.translation() + size * u);
      break;
    case ScanChange::one_rotation:
      chunk[k] = chunk[k] * RigidTransform(Rotation::exp(size * u), Eigen::Vector3d::Zero());
      break;
    case ScanChange::whole_rotation: {
      const Rotation R = Rotation::exp(size * u);
      const Eigen::Vector3d& pivot = chunk.front().translation();
      const RigidTransform h(R, pivot - R * pivot);
      for (RigidTransform& T : chunk) T = h * T;
      break;
    }
  }
  return chunk;
}

std::string describe(ScanChange change, double size) {
  const std::string amount = format_resolution(size, in_metres(change) ? "m" : "rad");
  switch (change) {
    case ScanChange::one_translation:
      return "one pose's translation moved by " + amount;
    case ScanChange::whole_translation:
      return "the whole chunk moved by " + amount;
    case ScanChange::one_rotation:
      return "one pose's rotation turned by " + amount;
    case ScanChange::whole_rotation:
      break;
  }
  return "the whole chunk turned by " + amount + " about its first pose";
}

using detail::chunk_distance;
using detail::inf_distance;

// A uniform number in [0, 1) in steps of 2^-30, as the scene generators draw.
double unit_fraction() {
  constexpr int kSteps = 1 << 30;
  return static_cast<double>(*uniform_integer(0, kSteps)) / kSteps;
}

// What the resolution scan found, per unit (0: m, 1: rad): the largest colliding size and its
// pair, and per decade the pairs drawn and how many of them collided.
struct Scan {
  std::array<double, 2> largest = {0.0, 0.0};
  std::array<std::optional<Collision>, 2> at_largest;
  std::vector<ScaleCollisions> scales;  // decade i, unit u at 2 i + u
};

// One resolution pair: `first` and `first` with its chunk changed by `size`. Sets `tried` when
// the tolerance can tell the two chunks apart; returns the pair when their actions collide.
std::optional<Collision> collide(const Representation& representation, const Scene& first,
                                 const Eigen::VectorXd& a, ScanChange change, std::size_t k,
                                 const Eigen::Vector3d& u, double size, double relative,
                                 bool& tried) {
  Scene second = first;
  second.world_T_hand_chunk = scaled_change(first.world_T_hand_chunk, change, k, u, size);
  const double tolerance = pointwise_tolerance(first, second, relative);
  tried = size > kPairMargin * tolerance;
  if (!tried) return std::nullopt;
  const Eigen::VectorXd b = representation.encode_actions(second);
  const double action_distance = inf_distance(a, b);
  if (!(action_distance <= tolerance)) return std::nullopt;
  const double apart = chunk_distance(first.world_T_hand_chunk, second.world_T_hand_chunk);
  return Collision{
      first, second, a, b, apart, action_distance, tolerance, describe(change, size), "resolution"};
}

Scan scan_resolution(const Representation& representation, const CheckOptions& options,
                     const std::vector<double>& decades, int scenes) {
  auto fresh = [&decades] {
    Scan out;
    for (double decade : decades) {
      out.scales.push_back(ScaleCollisions{decade, "m", 0, 0});
      out.scales.push_back(ScaleCollisions{decade, "rad", 0, 0});
    }
    return out;
  };
  Scan out = fresh();
  const double largest_size = 10.0 * *std::max_element(decades.begin(), decades.end());
  std::exception_ptr error;
  struct Pair {
    ScanChange change;
    std::size_t unit;
    double size;
    std::size_t k;
    Eigen::Vector3d u;
  };
  auto property = [&] {
    if (error) return;
    const Scene first = *shaped_scene(options.shape);
    // Every pair's draws first, in the order of the loop below, so that a batched map can be
    // asked for all the pairs' scenes at once.
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < decades.size(); ++i) {
      for (int c = 0; c < kScanChanges; ++c) {
        const auto change = static_cast<ScanChange>(c);
        const std::size_t unit = in_metres(change) ? 0 : 1;
        const double size = decades[i] * std::pow(10.0, unit_fraction());
        const auto k = static_cast<std::size_t>(*uniform_integer(0, first.chunk_length()));
        const Eigen::Vector3d u = *haar_rotation() * Eigen::Vector3d::UnitX();
        pairs.push_back({change, unit, size, k, u});
      }
    }
    ask_ahead(
        [&] {
          std::vector<Scene> asked = {first};
          for (const Pair& pair : pairs) {
            Scene second = first;
            second.world_T_hand_chunk =
                scaled_change(first.world_T_hand_chunk, pair.change, pair.k, pair.u, pair.size);
            if (pair.size >
                kPairMargin * pointwise_tolerance(first, second, options.relative_tolerance))
              asked.push_back(std::move(second));
          }
          return asked;
        },
        [&](const Scene& s) { return representation.encode_actions(s); });
    try {
      const Eigen::VectorXd a = representation.encode_actions(first);
      for (std::size_t p = 0; p < pairs.size(); ++p) {
        const Pair& pair = pairs[p];
        bool tried = false;
        std::optional<Collision> collision =
            collide(representation, first, a, pair.change, pair.k, pair.u, pair.size,
                    options.relative_tolerance, tried);
        ScaleCollisions& counts = out.scales[2 * (p / kScanChanges) + pair.unit];
        counts.pairs += tried ? 1 : 0;
        if (!collision) continue;
        ++counts.collisions;
        // Regrow the pair past the largest size found so far while it still collides.
        double at = pair.size;
        for (double next = std::max(pair.size, out.largest[pair.unit]) * kGrowth;
             next <= largest_size; next *= kGrowth) {
          std::optional<Collision> grown = collide(representation, first, a, pair.change, pair.k,
                                                   pair.u, next, options.relative_tolerance, tried);
          if (!grown) break;
          at = next;
          collision = std::move(grown);
        }
        if (at > out.largest[pair.unit]) {
          out.largest[pair.unit] = at;
          out.at_largest[pair.unit] = std::move(collision);
        }
      }
    } catch (const Error&) {
      error = std::current_exception();
    }
  };
  const std::string description = "resolution of " + representation.name();
  detail::answer_property_ahead(
      options.prefetch, property,
      [&] {
        out = fresh();
        error = nullptr;
      },
      description, options.seed, scenes);
  detail::run_silently(property, description, options.seed, scenes);
  if (error) std::rethrow_exception(error);
  return out;
}

}  // namespace

Injectivity check_injectivity(std::shared_ptr<const Representation> representation,
                              const CheckOptions& options, const ResolutionOptions& resolution) {
  if (!representation) throw InvalidArgument("check_injectivity needs a representation, got null");
  if (options.cases < 1)
    throw InvalidArgument("check_injectivity needs at least 1 case, got " +
                          std::to_string(options.cases));
  for (double decade : resolution.decades) {
    if (!(decade > 0.0 && std::isfinite(decade)))
      throw InvalidArgument("check_injectivity needs positive finite decades, got " +
                            format_number(decade));
  }
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
    const Scene first = *shaped_scene(shape);
    const auto change = static_cast<Change>(*uniform_integer(0, 4));
    const int index = *uniform_integer(0, 64);
    const Eigen::Vector3d v = *translation(1.0), w = *translation(1.0);
    const Rotation R = *rotation();
    Scene second = first;
    second.world_T_hand_chunk = changed_chunk(first, change, index, v, w, R);
    // Both scenes the case asks for (the second only if it is a pair, as below), named ahead
    // for a batched map; the decode round trip is asked one at a time.
    ask_ahead(
        [&] {
          const double apart = chunk_distance(first.world_T_hand_chunk, second.world_T_hand_chunk);
          const double scale = 1.0 + std::max(length_scale(first), length_scale(second));
          std::vector<Scene> asked = {first};
          if (apart >=
              std::max(1e-6 * scale, kPairMargin * pointwise_tolerance(first, second, relative)))
            asked.push_back(second);
          return asked;
        },
        [&](const Scene& s) { return representation->encode_actions(s); });
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
      const double tolerance = pointwise_tolerance(first, second, relative);
      // The change did nothing measurable, or nothing the tolerance can tell: not a pair.
      if (apart < std::max(1e-6 * scale, kPairMargin * tolerance)) return;
      const Eigen::VectorXd b = representation->encode_actions(second);
      if (searching) ++result.cases;
      const double action_distance = inf_distance(a, b);
      if (action_distance <= tolerance) {
        searching = false;
        result.collision = Collision{first,     second,           a,      b, apart, action_distance,
                                     tolerance, describe(change), "pairs"};
        RC_FAIL("two chunks, one action vector");
      }
    } catch (const Error&) {
      error = std::current_exception();
    }
  };
  const std::string description = "injectivity of " + representation->name();
  detail::answer_property_ahead(
      options.prefetch, property,
      [&] {
        result = Injectivity{};
        searching = true;
        shrink_evaluations = 0;
        error = nullptr;
      },
      description, options.seed, options.cases);
  detail::run_silently(property, description, options.seed, options.cases);
  if (error) std::rethrow_exception(error);

  Scan scan;
  if (!resolution.decades.empty()) {
    const int scenes = resolution.scenes > 0 ? resolution.scenes : std::max(10, options.cases / 8);
    scan = scan_resolution(*representation, options, resolution.decades, scenes);
  }
  int scan_pairs = 0;
  for (const ScaleCollisions& counts : scan.scales) scan_pairs += counts.pairs;
  result.scales = scan.scales;
  if (scan.largest[0] > 0.0) result.translation_resolution = scan.largest[0];
  if (scan.largest[1] > 0.0) result.rotation_resolution = scan.largest[1];
  const auto loses = [](const std::optional<double>& r) { return r && *r >= kSmallestLoss; };
  std::size_t unit = 0;
  if (result.translation_resolution &&
      (loses(result.translation_resolution) || !loses(result.rotation_resolution))) {
    result.resolution = result.translation_resolution;
    result.resolution_unit = "m";
  } else if (result.rotation_resolution) {
    unit = 1;
    result.resolution = result.rotation_resolution;
    result.resolution_unit = "rad";
  }
  const std::string resolution_text =
      result.resolution ? format_resolution(*result.resolution, result.resolution_unit) : "";
  // Rounding-level collisions (below kSmallestLoss) are named after the verdict.
  const std::string no_collision =
      "no collision among " + std::to_string(result.cases) + " chunk pairs and " +
      std::to_string(scan_pairs) + " resolution pairs" +
      (result.resolution ? " at changes of " + format_number(kSmallestLoss) + " or more" : "");

  // A pair apart by no more than the resolution is one of the scan's collisions, found first:
  // the loss is then named by the resolution, with the scan's pair at it as the witness.
  const bool below_resolution = result.collision && loses(result.resolution) &&
                                result.collision->chunk_distance <= *result.resolution;
  if (result.collision && !below_resolution) {
    result.injective = false;
    result.how = "two different chunks (apart by " +
                 format_number(result.collision->chunk_distance) +
                 ") with the same observation map to one action vector: the map loses information";
    if (loses(result.resolution))
      result.how += "; changes up to " + resolution_text + " collide as well";
  } else if (loses(result.resolution)) {
    result.injective = false;
    result.collision = scan.at_largest[unit];
    result.how = "chunks that differ by up to " + resolution_text + " (" +
                 result.collision->change +
                 ") map to one action vector: the map loses information below that";
  } else if (decodes && !result.round_trip_failure && result.round_trips > 0) {
    result.injective = true;
    result.how = "decode(encode(s)) gave back the chunk on all " +
                 std::to_string(result.round_trips) + " scenes, and " + no_collision;
  } else {
    result.how = no_collision + ", but " +
                 (decodes ? "decode(encode(s)) did not give back the chunk (see round_trip_failure)"
                          : "without a decoder that cannot prove the map injective");
  }
  if (result.resolution && !loses(result.resolution)) {
    result.how += "; changes up to " + resolution_text + " collided, below " +
                  format_resolution(kSmallestLoss, result.resolution_unit) +
                  ": rounding, not a loss of information";
  }
  return result;
}

std::string format_resolution(double value, const std::string& unit) {
  std::string text =
      format_scientific(value, 1);  // e.g. 7.8e-03: drop the exponent's leading zeros
  const std::size_t e = text.find('e');
  if (e != std::string::npos && e + 2 < text.size()) {
    std::size_t digits = e + 2;
    while (digits + 1 < text.size() && text[digits] == '0') text.erase(digits, 1);
    if (text[e + 1] == '+') text.erase(e + 1, 1);
  }
  return text + " " + unit;
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
