#pragma once
// Certificates: an equation between two exact expressions, checked with no tolerance.
//
//   identity       : lhs(x) = rhs(x) for a *generic* instance x (symbols everywhere: generic
//                    rotations R(q), translations, points, noise, time). Verified when every
//                    entry of lhs - rhs is identically 0 as a rational function: denominators
//                    are cleared and the numerator polynomial expands to exactly 0 (falling back
//                    to GiNaC's canonical normal() form), so "0" is exact, not "small".
//   counterexample : lhs(w) != rhs(w) for one concrete witness w (rational rotations and
//                    vectors). Verified when some entry of lhs - rhs is certainly nonzero: a
//                    nonzero rational, or a constant in Q(sqrt(3), pi) whose 50-digit value is
//                    above 1e-30 (the evaluation error is below 1e-45, so its sign is certain).
//
// Invariance of a flow f under a group is the identity f(g * scene, eps) = f(scene, eps); its
// failure is a counterexample with a witness (scene, g, eps).
#include <ginac/ginac.h>

#include <functional>
#include <string>
#include <utility>

#include "handcentric/proofs/exact_pose.hpp"

namespace handcentric::proofs {

/// One assignment of everything a claim may read: a scene, a global transform g = T~, the
/// noise eps (3x1) and the flow time t.
struct Instance {
  ExactScene scene;
  ExactPose g;
  GiNaC::matrix eps = column(0, 0, 0);
  GiNaC::ex t = 0;
};

/// The global transforms an identity is proved for.
enum class Group { translations, rotations, rigid_motions };

/// "translations", "rotations about the origin", "SE(3)".
std::string group_name(Group group);

/// A generic instance: T_0, T_{-1}, T_k generic poses; one world point and one eye-in-hand
/// point; symbolic eps and t; g generic in `group` (R~ = I for translations, p~ = 0 for rotations).
Instance generic_instance(Group group);

/// One side of an equation, as a column of exact expressions.
using Side = std::function<GiNaC::matrix(const Instance&)>;

/// A flow (or any representation component) of a scene.
using Flow = std::function<GiNaC::matrix(const ExactScene& scene, const GiNaC::matrix& eps,
                                         const GiNaC::ex& t)>;

/// A flow component of the scene and eps only (flows.hpp), as a Flow that ignores t.
inline Flow with_noise(GiNaC::matrix (*f)(const ExactScene&, const GiNaC::matrix&)) {
  return [f](const ExactScene& scene, const GiNaC::matrix& eps, const GiNaC::ex&) {
    return f(scene, eps);
  };
}

/// A component of the scene only (flows.hpp), as a Flow that ignores eps and t.
inline Flow ignoring_noise(GiNaC::matrix (*f)(const ExactScene&)) {
  return [f](const ExactScene& scene, const GiNaC::matrix&, const GiNaC::ex&) { return f(scene); };
}

/// lhs = f(g * scene, eps, t)
Side moved(const Flow& flow);
/// rhs = f(scene, eps, t)
Side unmoved(const Flow& flow);

/// How a counterexample's witness is shown: its inputs in words, and what each side is
/// (e.g. "f(T~ scene)" and "f(scene)").
struct WitnessText {
  WitnessText(std::string inputs_text = "", std::string lhs = "lhs",
              std::string rhs = "rhs")  // NOLINT
      : inputs(std::move(inputs_text)), lhs_name(std::move(lhs)), rhs_name(std::move(rhs)) {}
  WitnessText(const char* inputs_text) : WitnessText(std::string(inputs_text)) {}  // NOLINT
  std::string inputs;
  std::string lhs_name;
  std::string rhs_name;
};

/// What a certificate check found.
struct CertificateResult {
  bool verified = false;
  std::string witness;  ///< counterexample: the exact witness and both sides; empty otherwise
  std::string detail;   ///< how it was decided (first nonzero entry, etc.)
};

/// lhs - rhs simplifies to 0, entry by entry.
CertificateResult certify_identity(const Side& lhs, const Side& rhs, const Instance& generic);

/// lhs - rhs has a certainly-nonzero entry at the witness. The witness text lists the inputs
/// and both sides, named as `text` says. Throws InvalidArgument when the witness
/// still contains symbols.
CertificateResult certify_counterexample(const Side& lhs, const Side& rhs, const Instance& witness,
                                         const WitnessText& text);

/// True when the expression is identically 0 as a rational function: its numerator, after
/// clearing the denominators, expands to 0 (normal() where that does not apply).
bool is_identically_zero(const GiNaC::ex& value);

/// True when the symbol-free constant is certainly nonzero (see above).
bool is_certainly_nonzero(const GiNaC::ex& value);

/// A matrix or expression as GiNaC prints it: [[1,0,0],[0,3/5,-4/5],...].
std::string exact_text(const GiNaC::ex& value);

}  // namespace handcentric::proofs
