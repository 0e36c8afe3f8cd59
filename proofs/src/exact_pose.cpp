#include "handcentric/proofs/exact_pose.hpp"

#include <algorithm>
#include <sstream>
#include <utility>

namespace handcentric::proofs {

GiNaC::matrix column(const GiNaC::ex& x, const GiNaC::ex& y, const GiNaC::ex& z) {
  return GiNaC::matrix{{x}, {y}, {z}};
}

GiNaC::matrix stack(const GiNaC::matrix& top, const GiNaC::matrix& bottom) {
  GiNaC::matrix out(top.rows() + bottom.rows(), 1);
  for (unsigned i = 0; i < top.rows(); ++i) out(i, 0) = top(i, 0);
  for (unsigned i = 0; i < bottom.rows(); ++i) out(top.rows() + i, 0) = bottom(i, 0);
  return out;
}

GiNaC::matrix identity3() {
  return GiNaC::matrix{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}

ExactPose ExactPose::operator*(const ExactPose& other) const {
  return ExactPose{R.mul(other.R), R.mul(other.p).add(p)};
}

GiNaC::matrix ExactPose::operator*(const GiNaC::matrix& point) const {
  return R.mul(point).add(p);
}

ExactPose ExactPose::inverse() const {
  const GiNaC::matrix Rt = R.transpose();
  return ExactPose{Rt, Rt.mul(p).mul_scalar(-1)};
}

GiNaC::matrix ExactPose::entries() const {
  GiNaC::matrix out(12, 1);
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) out(3 * i + j, 0) = R(i, j);
  }
  for (unsigned i = 0; i < 3; ++i) out(9 + i, 0) = p(i, 0);
  return out;
}

namespace {

std::string printed(const GiNaC::ex& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// One product term as (sorted factors, rational coefficient).
std::pair<std::string, GiNaC::numeric> canonical_term(const GiNaC::ex& term) {
  GiNaC::numeric coefficient = 1;
  std::vector<std::string> factors;
  const auto take = [&](const GiNaC::ex& factor) {
    if (GiNaC::is_a<GiNaC::numeric>(factor)) {
      coefficient *= GiNaC::ex_to<GiNaC::numeric>(factor);
    } else {
      factors.push_back(printed(factor));
    }
  };
  if (GiNaC::is_a<GiNaC::mul>(term)) {
    for (std::size_t i = 0; i < term.nops(); ++i) take(term.op(i));
  } else {
    take(term);
  }
  std::sort(factors.begin(), factors.end());
  std::string key;
  for (const std::string& factor : factors) key += (key.empty() ? "" : "*") + factor;
  return {key, coefficient};
}

}  // namespace

std::string canonical_text(const GiNaC::ex& value) {
  // GiNaC orders the terms of a sum by hash values that depend on the process, so the printed
  // order can change between programs: sort terms and factors by their text instead.
  const GiNaC::ex expanded = GiNaC::expand(value);
  std::vector<std::pair<std::string, GiNaC::numeric>> terms;
  if (GiNaC::is_a<GiNaC::add>(expanded)) {
    for (std::size_t i = 0; i < expanded.nops(); ++i)
      terms.push_back(canonical_term(expanded.op(i)));
  } else {
    terms.push_back(canonical_term(expanded));
  }
  std::sort(terms.begin(), terms.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string out;
  for (const auto& [key, coefficient] : terms) {
    const bool negative = coefficient < 0;
    const GiNaC::numeric magnitude = negative ? GiNaC::numeric(-coefficient) : coefficient;
    std::string term;
    if (key.empty()) {
      term = printed(magnitude);
    } else if (magnitude == 1) {
      term = key;
    } else {
      term = printed(magnitude) + "*" + key;
    }
    if (out.empty()) {
      out = (negative ? "-" : "") + term;
    } else {
      out += (negative ? " - " : " + ") + term;
    }
  }
  return out.empty() ? "0" : out;
}

std::string matrix_text(const GiNaC::matrix& m) {
  std::string out = "[";
  for (unsigned i = 0; i < m.rows(); ++i) {
    out += i ? ", [" : "[";
    for (unsigned j = 0; j < m.cols(); ++j) out += (j ? ", " : "") + canonical_text(m(i, j));
    out += "]";
  }
  return out + "]";
}

std::string column_text(const GiNaC::matrix& v) {
  std::string out = "(";
  for (unsigned i = 0; i < v.rows(); ++i) out += (i ? ", " : "") + canonical_text(v(i, 0));
  return out + ")";
}

std::string pose_text(const ExactPose& pose) {
  std::ostringstream out;
  bool identity = true;
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j)
      identity = identity && (pose.R(i, j) - (i == j ? 1 : 0)).is_zero();
  }
  out << "[";
  if (identity) {
    out << "I";
  } else {
    out << matrix_text(pose.R);
  }
  out << " | " << column_text(pose.p) << "]";
  return out.str();
}

ExactPose translation_pose(const GiNaC::matrix& p) {
  return ExactPose{identity3(), p};
}

ExactPose rotation_pose(const GiNaC::matrix& R) {
  return ExactPose{R, column(0, 0, 0)};
}

ExactScene operator*(const ExactPose& g, const ExactScene& scene) {
  ExactScene out = scene;
  for (ExactPose& world_T_hand : out.history) world_T_hand = g * world_T_hand;
  for (ExactPose& world_T_hand : out.chunk) world_T_hand = g * world_T_hand;
  for (GiNaC::matrix& point_world : out.world_points) point_world = g * point_world;
  return out;  // hand_points unchanged
}

}  // namespace handcentric::proofs
