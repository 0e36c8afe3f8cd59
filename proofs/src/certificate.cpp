#include "handcentric/proofs/certificate.hpp"

#include <exception>
#include <sstream>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/proofs/quaternion_rotation.hpp"

namespace handcentric::proofs {
namespace {

constexpr int kDigits = 50;                 // evaluation precision of a non-rational constant
const char* const kNonzeroBound = "1e-30";  // well above the 50-digit evaluation error

bool has_symbols(const GiNaC::ex& value) {
  for (auto it = value.preorder_begin(); it != value.preorder_end(); ++it) {
    if (GiNaC::is_a<GiNaC::symbol>(*it)) return true;
  }
  return false;
}

void require_same_shape(const GiNaC::matrix& lhs, const GiNaC::matrix& rhs) {
  if (lhs.rows() != rhs.rows() || lhs.cols() != rhs.cols()) {
    throw InvalidArgument("certificate: the two sides have shapes " + std::to_string(lhs.rows()) +
                          "x" + std::to_string(lhs.cols()) + " and " + std::to_string(rhs.rows()) +
                          "x" + std::to_string(rhs.cols()) + "; a claim must compare equal shapes");
  }
}

}  // namespace

std::string exact_text(const GiNaC::ex& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string group_name(Group group) {
  switch (group) {
    case Group::translations:
      return "translations";
    case Group::rotations:
      return "rotations about the origin";
    case Group::rigid_motions:
      return "SE(3)";
  }
  return "?";
}

Instance generic_instance(Group group) {
  Instance instance;
  instance.scene.history = {generic_pose("0"), generic_pose("m1")};  // T_0, T_{-1}
  instance.scene.chunk = {generic_pose("k")};                        // T_k
  instance.scene.world_points = {generic_vector("x")};
  instance.scene.hand_points = {generic_vector("y")};
  instance.eps = generic_vector("eps");
  instance.t = GiNaC::symbol("t");
  if (group != Group::translations) instance.g.R = generic_rotation("qg");
  if (group != Group::rotations) instance.g.p = generic_vector("pg");
  return instance;
}

Side moved(const Flow& flow) {
  return [flow](const Instance& x) { return flow(x.g * x.scene, x.eps, x.t); };
}

Side unmoved(const Flow& flow) {
  return [flow](const Instance& x) { return flow(x.scene, x.eps, x.t); };
}

bool is_identically_zero(const GiNaC::ex& value) {
  // Clear denominators: every base b of a negative power becomes a fresh symbol B, the Laurent
  // polynomial in the B's is multiplied by the lowest powers that make it a polynomial P(B),
  // and b is put back: P(b) = value * prod b^m. P(b) expanding to 0 proves value = 0; a nonzero
  // polynomial proves value != 0. Faster than normal() (no multivariate gcd); anything else
  // falls back to normal().
  try {
    GiNaC::exmap to_symbol;
    GiNaC::exmap back;
    std::vector<GiNaC::symbol> bases;
    for (auto it = value.preorder_begin(); it != value.preorder_end(); ++it) {
      if (!GiNaC::is_a<GiNaC::power>(*it) || !GiNaC::is_a<GiNaC::numeric>(it->op(1))) continue;
      const GiNaC::numeric exponent = GiNaC::ex_to<GiNaC::numeric>(it->op(1));
      if (!exponent.is_integer() || !exponent.is_negative() || to_symbol.count(it->op(0))) continue;
      const GiNaC::symbol base("denominator_" + std::to_string(bases.size()));
      to_symbol[it->op(0)] = base;
      back[base] = it->op(0);
      bases.push_back(base);
    }
    GiNaC::ex laurent = GiNaC::expand(value.subs(to_symbol));
    GiNaC::ex multiplier = 1;
    for (const GiNaC::symbol& base : bases) {
      const int lowest = laurent.ldegree(base);
      if (lowest < 0) multiplier *= GiNaC::pow(base, -lowest);
    }
    const GiNaC::ex numerator = GiNaC::expand(GiNaC::expand(laurent * multiplier).subs(back));
    if (numerator.is_zero()) return true;
    if (numerator.info(GiNaC::info_flags::polynomial)) return false;
  } catch (const std::exception&) {
    // not a Laurent polynomial in the denominators: use the general normal form below
  }
  return GiNaC::normal(value).is_zero();
}

bool is_certainly_nonzero(const GiNaC::ex& value) {
  const GiNaC::ex simplified = GiNaC::normal(value);
  if (GiNaC::is_a<GiNaC::numeric>(simplified) &&
      GiNaC::ex_to<GiNaC::numeric>(simplified).is_rational()) {
    return !simplified.is_zero();
  }
  if (has_symbols(simplified)) return false;
  const long previous = GiNaC::Digits;
  GiNaC::Digits = kDigits;
  const GiNaC::ex approx = GiNaC::evalf(simplified);
  GiNaC::Digits = previous;
  if (!GiNaC::is_a<GiNaC::numeric>(approx)) return false;
  return GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(approx)) > GiNaC::numeric(kNonzeroBound);
}

CertificateResult certify_identity(const Side& lhs, const Side& rhs, const Instance& generic) {
  const GiNaC::matrix left = lhs(generic);
  const GiNaC::matrix right = rhs(generic);
  require_same_shape(left, right);
  for (unsigned i = 0; i < left.rows(); ++i) {
    for (unsigned j = 0; j < left.cols(); ++j) {
      if (!is_identically_zero(left(i, j) - right(i, j))) {
        std::string residual = exact_text(GiNaC::normal(left(i, j) - right(i, j)));
        if (residual.size() > 160) residual = residual.substr(0, 157) + "...";
        return {false, "",
                "entry " + std::to_string(i) + " of lhs - rhs does not simplify to 0: " + residual};
      }
    }
  }
  return {true, "",
          "all " + std::to_string(left.rows() * left.cols()) +
              " entries of lhs - rhs are identically 0 (denominators cleared, numerator expanded)"};
}

CertificateResult certify_counterexample(const Side& lhs, const Side& rhs, const Instance& witness,
                                         const WitnessText& text) {
  const GiNaC::matrix left = lhs(witness);
  const GiNaC::matrix right = rhs(witness);
  require_same_shape(left, right);
  GiNaC::matrix left_simplified(left.rows(), left.cols());
  GiNaC::matrix right_simplified(left.rows(), left.cols());
  int differing = -1;
  for (unsigned i = 0; i < left.rows(); ++i) {
    for (unsigned j = 0; j < left.cols(); ++j) {
      left_simplified(i, j) = GiNaC::normal(left(i, j));
      right_simplified(i, j) = GiNaC::normal(right(i, j));
      if (has_symbols(left_simplified(i, j)) || has_symbols(right_simplified(i, j))) {
        throw InvalidArgument("certificate: the witness " + text.inputs +
                              " leaves symbols in the claim; give every input an exact value");
      }
      if (differing < 0 && is_certainly_nonzero(left(i, j) - right(i, j))) {
        differing = static_cast<int>(i * left.cols() + j);
      }
    }
  }
  const auto shown = [](const GiNaC::matrix& m) {
    return m.cols() == 1 ? column_text(m) : matrix_text(m);
  };
  const std::string both = text.inputs + "; " + text.lhs_name + " = " + shown(left_simplified) +
                           ", " + text.rhs_name + " = " + shown(right_simplified);
  if (differing < 0)
    return {false, both, "both sides are equal at this witness: not a counterexample"};
  return {true, both, "entry " + std::to_string(differing) + " of the two sides certainly differs"};
}

}  // namespace handcentric::proofs
