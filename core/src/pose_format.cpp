#include "handcentric/core/pose_format.hpp"

#include <Eigen/Geometry>
#include <cctype>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric {
namespace {

constexpr const char* kAxisNames = "xyz";

struct Named {
  const char* name;
  PoseFormat::Kind kind;
  int width;
};
constexpr Named kNamed[] = {
    {"matrix", PoseFormat::Kind::matrix, 16},
    {"pos_quat_xyzw", PoseFormat::Kind::pos_quat_xyzw, 7},
    {"pos_quat_wxyz", PoseFormat::Kind::pos_quat_wxyz, 7},
    {"pos_axis_angle", PoseFormat::Kind::pos_axis_angle, 6},
    {"pos_rot6d_rows", PoseFormat::Kind::pos_rot6d_rows, 9},
    {"pos_rot6d_cols", PoseFormat::Kind::pos_rot6d_cols, 9},
    {"pos_euler_", PoseFormat::Kind::pos_euler, 6},
};
constexpr const char* kEulerPrefix = "pos_euler_";

const Named& named(PoseFormat::Kind kind) {
  for (const Named& n : kNamed)
    if (n.kind == kind) return n;
  return kNamed[0];
}

// The angle of R_axis(angle) = M, read from the plane the axis turns: with (axis, u, w) cyclic,
// M(u, u) = cos(angle) and M(w, u) = sin(angle).
double angle_about(int axis, const Eigen::Matrix3d& M) {
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  return std::atan2(M(w, u), M(u, u));
}

// Intrinsic angles (a, b, c) with R = R_i(a) R_j(b) R_k(c) for axes (i, j, k), j != i, k != j.
// Three different axes (Tait-Bryan): b in [-pi/2, pi/2] from row i; two equal (proper Euler,
// k = i): b in [0, pi]. a from the column the last rotation leaves alone (the k-th, or the i-th
// when k = i); c from what R_i(a) R_j(b) leaves, so the three always compose back to R. At
// gimbal lock (cos b = 0, or sin b = 0 for proper Euler) a and c turn one axis, c is set to 0.
Eigen::Vector3d intrinsic_angles(const Eigen::Matrix3d& R, const std::array<int, 3>& axes) {
  const int i = axes[0], j = axes[1], k = axes[2];
  const bool proper = (k == i);
  const int third = 3 - i - j;                           // the axis neither i nor j
  const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;  // (i, j, third) an even permutation
  double a = 0.0, b = 0.0;
  bool locked = false;
  if (!proper) {
    const double cos_b = std::hypot(R(i, i), R(i, j));
    b = std::atan2(s * R(i, k), cos_b);
    locked = cos_b < 1e-9;
    if (!locked) a = std::atan2(-s * R(j, k), R(k, k));
  } else {
    const double sin_b = std::hypot(R(i, j), R(i, third));
    b = std::atan2(sin_b, R(i, i));
    locked = sin_b < 1e-9;
    if (!locked) a = std::atan2(R(j, i), -s * R(third, i));
  }
  double c = 0.0;
  if (locked) {
    a = angle_about(i, R * axis_rotation(j, b).transpose());
  } else {
    c = angle_about(k, (axis_rotation(i, a) * axis_rotation(j, b)).transpose() * R);
  }
  return {a, b, c};
}

[[noreturn]] void contradicted(const std::string& what, const Eigen::VectorXd& v,
                               const PoseFormat& format, const std::string& wrong,
                               const std::string& fix) {
  throw InvalidArgument(what + " = " + format_readable(v) + " is not a pose in " + format.name() +
                        ": " + wrong + "; " + fix);
}

bool near(double value, double target) {
  return std::abs(value - target) <= kLayoutTolerance;
}

// The rotation whose first two rows (rows) or columns are a and b, orthonormalized.
Eigen::Matrix3d from_6d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, bool rows) {
  const Eigen::Vector3d e1 = a.normalized();
  const Eigen::Vector3d e2 = (b - e1.dot(b) * e1).normalized();
  const Eigen::Vector3d e3 = e1.cross(e2);
  Eigen::Matrix3d M;
  M.col(0) = e1, M.col(1) = e2, M.col(2) = e3;
  return rows ? Eigen::Matrix3d(M.transpose()) : M;
}

}  // namespace

Eigen::Matrix3d axis_rotation(int axis, double angle) {
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R(u, u) = c, R(u, w) = -s;
  R(w, u) = s, R(w, w) = c;
  return R;
}

std::string PoseFormat::name() const {
  if (kind != Kind::pos_euler) return named(kind).name;
  std::string axes_text;
  for (int a : axes) {
    const char c = kAxisNames[a];
    axes_text += intrinsic ? static_cast<char>(c - 'a' + 'A') : c;
  }
  return kEulerPrefix + axes_text;
}

int PoseFormat::width() const {
  return named(kind).width;
}

std::vector<std::string> pose_format_names() {
  std::vector<std::string> out;
  for (const Named& n : kNamed)
    out.push_back(n.kind == PoseFormat::Kind::pos_euler ? std::string(kEulerPrefix) + "<axes>"
                                                        : std::string(n.name));
  return out;
}

PoseFormat parse_pose_format(const std::string& text, const std::string& keyword) {
  std::string known;
  for (const std::string& n : pose_format_names()) known += (known.empty() ? "" : ", ") + n;
  const std::string euler_rule =
      "<axes> is three of x, y, z as SciPy spells them, no axis twice in a row: lowercase "
      "about the fixed axes (extrinsic), uppercase about the moving ones (intrinsic), e.g. "
      "pos_euler_xyz or pos_euler_ZYX";
  PoseFormat format;
  if (text.rfind(kEulerPrefix, 0) == 0) {
    const std::string axes = text.substr(std::string(kEulerPrefix).size());
    const auto bad = [&](const std::string& why) {
      return InvalidArgument(keyword + "='" + text + "': " + why + "; " + euler_rule);
    };
    if (axes.size() != 3) throw bad("the axes '" + axes + "' are not three letters");
    const bool upper = std::isupper(static_cast<unsigned char>(axes[0])) != 0;
    for (int n = 0; n < 3; ++n) {
      const char c = axes[static_cast<std::size_t>(n)];
      const char lower = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (lower < 'x' || lower > 'z') throw bad(std::string("'") + c + "' is not an axis");
      if ((std::isupper(static_cast<unsigned char>(c)) != 0) != upper)
        throw bad("the axes '" + axes + "' mix lowercase and uppercase");
      format.axes[static_cast<std::size_t>(n)] = lower - 'x';
    }
    if (format.axes[0] == format.axes[1] || format.axes[1] == format.axes[2])
      throw bad("the axes '" + axes + "' turn about one axis twice in a row");
    format.kind = PoseFormat::Kind::pos_euler;
    format.intrinsic = upper;
    return format;
  }
  for (const Named& n : kNamed) {
    if (n.kind != PoseFormat::Kind::pos_euler && text == n.name) {
      format.kind = n.kind;
      return format;
    }
  }
  throw InvalidArgument(keyword + "='" + text + "' is not a pose format; the formats are " + known +
                        " (" + euler_rule + ")");
}

Eigen::VectorXd encode_pose(const RigidTransform& pose, const PoseFormat& format) {
  const Eigen::Matrix3d& R = pose.rotation().matrix();
  Eigen::VectorXd v(format.width());
  if (format.kind == PoseFormat::Kind::matrix) {
    const Eigen::Matrix4d M = pose.matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) v(4 * r + c) = M(r, c);
    return v;
  }
  v.head<3>() = pose.translation();
  switch (format.kind) {
    case PoseFormat::Kind::pos_quat_xyzw:
    case PoseFormat::Kind::pos_quat_wxyz: {
      Eigen::Quaterniond q(R);
      if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // w >= 0: one of the two quaternions of R
      if (format.kind == PoseFormat::Kind::pos_quat_xyzw)
        v.tail<4>() << q.x(), q.y(), q.z(), q.w();
      else
        v.tail<4>() << q.w(), q.x(), q.y(), q.z();
      break;
    }
    case PoseFormat::Kind::pos_axis_angle:
      v.tail<3>() = so3::log(R);
      break;
    case PoseFormat::Kind::pos_rot6d_rows:
      v.segment<3>(3) = R.row(0).transpose();
      v.segment<3>(6) = R.row(1).transpose();
      break;
    case PoseFormat::Kind::pos_rot6d_cols:
      v.segment<3>(3) = R.col(0);
      v.segment<3>(6) = R.col(1);
      break;
    case PoseFormat::Kind::pos_euler: {
      if (format.intrinsic) {
        v.tail<3>() = intrinsic_angles(R, format.axes);
      } else {
        // Extrinsic (a, b, c) about (i, j, k): R = R_k(c) R_j(b) R_i(a), the intrinsic angles
        // (c, b, a) about (k, j, i).
        const std::array<int, 3> reversed = {format.axes[2], format.axes[1], format.axes[0]};
        const Eigen::Vector3d cba = intrinsic_angles(R, reversed);
        v.tail<3>() << cba(2), cba(1), cba(0);
      }
      break;
    }
    case PoseFormat::Kind::matrix:
      break;
  }
  return v;
}

RigidTransform decode_pose(const Eigen::Ref<const Eigen::VectorXd>& vector,
                           const PoseFormat& format, const std::string& what) {
  const Eigen::VectorXd v = vector;
  if (v.size() != format.width()) {
    throw InvalidArgument(what + " has " + std::to_string(v.size()) + " numbers; a pose in " +
                          format.name() + " has " + std::to_string(format.width()));
  }
  if (!v.allFinite()) {
    throw InvalidArgument(what + " = " + format_readable(v) +
                          " has a non-finite number (nan or infinity)");
  }
  if (format.kind == PoseFormat::Kind::matrix) {
    const double row = std::abs(v(12)) + std::abs(v(13)) + std::abs(v(14)) + std::abs(v(15) - 1.0);
    if (!(row <= 1e-6)) {
      throw InvalidArgument(what + " has last row " + format_readable(v.tail<4>()) +
                            "; a pose is [[R, p], [0, 0, 0, 1]]");
    }
    Eigen::Matrix3d R;
    R << v(0), v(1), v(2), v(4), v(5), v(6), v(8), v(9), v(10);
    return RigidTransform::unchecked(R, Eigen::Vector3d(v(3), v(7), v(11)));
  }
  const Eigen::Vector3d p = v.head<3>();
  Eigen::Matrix3d R;
  switch (format.kind) {
    case PoseFormat::Kind::pos_quat_xyzw:
    case PoseFormat::Kind::pos_quat_wxyz: {
      const Eigen::Vector4d q = v.tail<4>();
      if (!near(q.norm(), 1.0)) {
        contradicted(what, v, format, "its quaternion has norm " + format_significant(q.norm(), 4),
                     "a rotation's quaternion has norm 1 (normalize it as your decoder does, or "
                     "declare the layout the policy uses: pos_axis_angle has 6 numbers, "
                     "pos_euler_<axes> 6)");
      }
      R = format.kind == PoseFormat::Kind::pos_quat_xyzw
              ? Rotation::from_quaternion(q(3), q(0), q(1), q(2)).matrix()
              : Rotation::from_quaternion(q(0), q(1), q(2), q(3)).matrix();
      break;
    }
    case PoseFormat::Kind::pos_axis_angle:
      R = so3::exp(v.tail<3>());
      break;
    case PoseFormat::Kind::pos_rot6d_rows:
    case PoseFormat::Kind::pos_rot6d_cols: {
      const Eigen::Vector3d a = v.segment<3>(3), b = v.segment<3>(6);
      const bool rows = format.kind == PoseFormat::Kind::pos_rot6d_rows;
      if (!near(a.norm(), 1.0) || !near(b.norm(), 1.0) || !near(a.dot(b), 0.0)) {
        contradicted(what, v, format,
                     std::string("its two ") + (rows ? "rows" : "columns") +
                         " are not orthonormal (norms " + format_significant(a.norm(), 4) +
                         " and " + format_significant(b.norm(), 4) + ", dot product " +
                         format_significant(a.dot(b), 4) + ")",
                     "orthonormalize them as your decoder does (Gram-Schmidt, e.g. PyTorch3D's "
                     "rotation_6d_to_matrix) before returning them");
      }
      R = from_6d(a, b, rows);
      break;
    }
    case PoseFormat::Kind::pos_euler: {
      const Eigen::Vector3d angles = v.tail<3>();
      R = Eigen::Matrix3d::Identity();
      // Intrinsic: R = R_i(a) R_j(b) R_k(c); extrinsic: R = R_k(c) R_j(b) R_i(a).
      for (int n = 0; n < 3; ++n) {
        const Eigen::Matrix3d turn =
            axis_rotation(format.axes[static_cast<std::size_t>(n)], angles(n));
        R = format.intrinsic ? Eigen::Matrix3d(R * turn) : Eigen::Matrix3d(turn * R);
      }
      break;
    }
    case PoseFormat::Kind::matrix:
      break;
  }
  return RigidTransform::unchecked(R, p);
}

}  // namespace handcentric
