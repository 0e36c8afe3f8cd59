#include "handcentric/props/verdict.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

// "r = [..], p = [..]" of a scene's pose: the rotation vector and the translation, readable (6
// digits, below 1e-9 (1 + the largest) as 0, where the off-case move lies: format_readable);
// the JSON keeps every bit.
std::string pose_text(const RigidTransform& T) {
  return "r = " + format_readable(T.rotation().log()) + ", p = " + format_readable(T.translation());
}

// g's pose text: g is drawn exactly and never moved off its case, so only what lies below 1e-9
// of its largest entry is noise (an edge case's 1e-12 rad stays visible).
std::string g_text(const RigidTransform& g) {
  const auto readable = [](const Eigen::Vector3d& v) {
    return format_readable(v, 6, 1e-9 * largest_magnitude(v));
  };
  return "r = " + readable(g.rotation().log()) + ", p = " + readable(g.translation());
}

// A long vector shows its first 12 entries and how many it has.
std::string vector_text(const Eigen::VectorXd& v, int digits, double noise) {
  if (v.size() <= 12) return format_readable(v, digits, noise);
  std::string text("(");
  text += std::to_string(v.size());
  text += " numbers) ";
  text += format_readable(v.head(12), digits, noise);
  text += " ...";
  return text;
}

// The digits at which before and after print apart where they differ most (6 at least): a
// difference of 1e-9 in entries near 1 shows in the text, not only in the error.
int before_after_digits(const Eigen::VectorXd& before, const Eigen::VectorXd& after) {
  if (before.size() != after.size() || before.size() == 0) return 6;
  Eigen::Index most = 0;
  (before - after).cwiseAbs().maxCoeff(&most);
  return digits_to_tell_apart(before(most), after(most));
}

}  // namespace

std::string to_string(Component component) {
  switch (component) {
    case Component::actions:
      return "actions";
    case Component::observation:
      return "observation";
    case Component::flow_input:
      return "flow_input";
    case Component::flow_target:
      return "flow_target";
    case Component::policy:
      return "policy";
  }
  return "?";
}

std::string to_string(Mode mode) {
  switch (mode) {
    case Mode::pointwise:
      return "pointwise";
    case Mode::distribution:
      return "distribution";
    case Mode::closed_loop:
      return "closed_loop";
  }
  return "pointwise";
}

std::vector<View> parse_views(const std::vector<std::string>& names, const std::string& option,
                              const Spelling& spelling) {
  std::vector<View> out;
  for (const std::string& name : names) {
    if (name == "all") return {View::eye_in_hand, View::third_person};
    if (name == "eye_in_hand" || name == "third_person") {
      out.push_back(name == "eye_in_hand" ? View::eye_in_hand : View::third_person);
    } else {
      throw InvalidArgument("unknown " + spelling.option(option) + " '" + name +
                            "'; use eye_in_hand, third_person or all");
    }
  }
  if (out.empty())
    throw InvalidArgument(spelling.option(option) +
                          " is empty; name eye_in_hand, third_person or both");
  return out;
}

std::string to_string(Method method) {
  switch (method) {
    case Method::compared:
      return "compared";
    case Method::exact_gaussian:
      return "exact_gaussian";
    case Method::energy_test:
      return "energy_test";
    case Method::partly_exact:
      return "partly_exact";
    case Method::from_pointwise:
      return "from_pointwise";
  }
  return "?";
}

std::string format_witness(const Witness& witness) {
  std::ostringstream out;
  const Scene& s = witness.scene;
  out << "g: " << g_text(witness.g) << "\n"
      << "scene: H = " << s.history_length() << ", K = " << s.chunk_length() << ", "
      << s.hand_points.size() << " eye-in-hand and " << s.world_points.size() << " world points\n";
  for (std::size_t h = 0; h < s.world_T_hand_history.size(); ++h) {
    out << "  T_" << (h == 0 ? "" : "-") << h << ": " << pose_text(s.world_T_hand_history[h])
        << "\n";
  }
  for (std::size_t k = 0; k < s.world_T_hand_chunk.size(); ++k) {
    out << "  T_" << k + 1 << ": " << pose_text(s.world_T_hand_chunk[k]) << "\n";
  }
  for (const auto& x : s.hand_points) out << "  eye-in-hand point: " << format_readable(x) << "\n";
  for (const auto& x : s.world_points) out << "  world point: " << format_readable(x) << "\n";
  for (const auto& [name, T] : s.extra_poses)
    out << "  extra pose '" << name << "': " << pose_text(T) << "\n";
  for (const auto& [name, value] : s.scalars)
    out << "  scalar '" << name << "': " << format_significant(value) << "\n";
  for (const auto& [name, array] : s.held)
    out << "  held array '" << name << "': " << array->describe() << " (unchanged by g)\n";
  const bool law = !witness.detail.empty();
  const int digits = before_after_digits(witness.before, witness.after);
  // Noise as in the scene's poses, but never as large as a thousandth of the error: the entry
  // that differs by the error stays (at least one side of it is error / 2 or more).
  const double noise = std::min(
      1e-9 * (1.0 + std::max(largest_magnitude(witness.before), largest_magnitude(witness.after))),
      1e-3 * witness.error);
  out << (law ? "mean before: " : "before: ") << vector_text(witness.before, digits, noise) << "\n"
      << (law ? "mean after:  " : "after:  ") << vector_text(witness.after, digits, noise) << "\n";
  // The error beside what it is compared with, at the digits that tell the two apart.
  const int compared = digits_to_tell_apart(witness.error, witness.tolerance);
  if (law) out << witness.detail << "\n";
  if (witness.p_value < 1.0) {
    const int p_digits = digits_to_tell_apart(witness.p_value, witness.tolerance);
    out << "energy distance " << format_significant(witness.error)
        << " (unitless statistic), permutation p = "
        << format_significant(witness.p_value, p_digits) << " < level "
        << format_significant(witness.tolerance, p_digits);
    return out.str();
  }
  out << "error " << format_significant(witness.error, compared)
      << " (largest difference; m, rad or the component's units) > tolerance "
      << format_significant(witness.tolerance, compared);
  if (witness.length_scale > 0.0)
    out << " = REL (1 + L) with L = " << format_significant(witness.length_scale) << " m";
  if (witness.rounding_response > 0.0) {
    out << "\nthe map's own rounding response here: "
        << format_significant(witness.rounding_response)
        << " (its outputs' change when the inputs move by a few units of rounding)";
  }
  // Off the case the difference persisted (check.cpp, decide_pointwise); whether that rules out
  // rounding depends on the map's rounding response there.
  if (witness.off_case && witness.rounding_response >= witness.error) {
    out << "\nthis scene is the case drawn, moved off it by a small random amount: the difference "
           "persists there, but the map's own rounding moves its output as much as g does: it "
           "sits on a discontinuity at every scene near this one (e.g. it bins a quantity that is "
           "on a bin edge by construction, or encodes an angle that jumps at pi), so this witness "
           "cannot tell a symmetry breaking from an output decided by rounding";
  } else if (witness.off_case) {
    out << "\nthis scene is the case drawn, moved off it by a small random amount: the "
           "difference persists there, so it is no bin edge or rounding";
  }
  // The case's own noise (policy_audit.hpp): what a replay outside the audit needs.
  if (witness.noise_seed) {
    out << "\nnoise: the case's own, the same for both sides: noise_seed " << *witness.noise_seed
        << " (the noise is props::fixed_noise(n, noise_seed), the first n normals of "
           "mt19937_64(noise_seed); a policy that takes a seed gets noise_seed itself)";
  }
  return out.str();
}

double detectable_frequency(int cases) {
  if (cases <= 0) return 1.0;
  return -std::expm1(std::log(0.01) / cases);  // 1 - 0.01^(1/n), accurate for large n
}

std::string pose_summary(const RigidTransform& T) {
  // 4 significant digits: enough to recognise a scene; the seed replays it exactly.
  const auto short_vector = [](const Eigen::Vector3d& v) {
    std::string text = "[";  // appends: GCC 12 warns, falsely, on "[" + std::string&&
    for (int i = 0; i < 3; ++i) {
      if (i > 0) text += ", ";
      text += format_significant(v[i], 4);
    }
    return text + "]";
  };
  return "(p = " + short_vector(T.translation()) + " m, r = " + short_vector(T.rotation().log()) +
         ")";
}

std::string observation_summary(const Scene& scene) {
  return "T_0 = " + pose_summary(scene.world_T_hand0()) +
         " with H = " + std::to_string(scene.history_length()) + ", " +
         std::to_string(scene.hand_points.size()) + " hand points, " +
         std::to_string(scene.world_points.size()) + " world points";
}

}  // namespace handcentric::props
