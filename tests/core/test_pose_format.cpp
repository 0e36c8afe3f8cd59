// PoseFormat: each layout's definition (hand-written matrices, not the library's own rotations),
// encode then decode gives the pose back on every layout and at gimbal lock, the ranges SciPy
// documents, and a vector that contradicts its layout is refused with its numbers.
#include <catch2/catch.hpp>

#include "throws.hpp"  // tests/support
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/pose_format.hpp"
#include "handcentric/core/sampling.hpp"

using namespace handcentric;

namespace {

constexpr double kPoseFormatPi = std::numbers::pi;

// Every layout there is: the fixed ones and the 24 Euler sequences (12 each way).
std::vector<PoseFormat> every_pose_format() {
  std::vector<PoseFormat> out;
  for (const char* name : {"matrix", "pos_quat_xyzw", "pos_quat_wxyz", "pos_axis_angle",
                           "pos_rot6d_rows", "pos_rot6d_cols"})
    out.push_back(parse_pose_format(name, "action_format"));
  const std::string letters = "xyz";
  for (char a : letters)
    for (char b : letters)
      for (char c : letters) {
        if (a == b || b == c) continue;
        const std::string lower = {a, b, c};
        const std::string upper = {static_cast<char>(a - 32), static_cast<char>(b - 32),
                                   static_cast<char>(c - 32)};
        out.push_back(parse_pose_format("pos_euler_" + lower, "action_format"));
        out.push_back(parse_pose_format("pos_euler_" + upper, "action_format"));
      }
  return out;
}

double pose_gap(const RigidTransform& a, const RigidTransform& b) {
  return (a.matrix() - b.matrix()).norm();
}

RigidTransform at(const Eigen::Matrix3d& R) {
  return RigidTransform::unchecked(R, Eigen::Vector3d(0.1, -0.2, 0.3));
}

}  // namespace

TEST_CASE("every_pose_format_is_named_back_as_parsed_with_its_width", "[unit]") {
  const std::vector<PoseFormat> formats = every_pose_format();
  CHECK(formats.size() == 6 + 24);
  for (const PoseFormat& f : formats) {
    CHECK(parse_pose_format(f.name(), "state_format") == f);
  }
  CHECK(parse_pose_format("matrix", "k").width() == 16);
  CHECK(parse_pose_format("pos_quat_xyzw", "k").width() == 7);
  CHECK(parse_pose_format("pos_axis_angle", "k").width() == 6);
  CHECK(parse_pose_format("pos_rot6d_cols", "k").width() == 9);
  CHECK(parse_pose_format("pos_euler_zyx", "k").width() == 6);
}

namespace {

using DecodeFn = Eigen::Matrix3d (*)(const std::string& name, const Eigen::VectorXd& v);

Eigen::Matrix3d library_decode(const std::string& name, const Eigen::VectorXd& v) {
  return decode_pose(v, parse_pose_format(name, "action_format"), "v").rotation().matrix();
}

// Planted faults, each a convention bug seen in shipped code: Euler angles composed in the other
// order (extrinsic read as intrinsic), a quaternion read with its scalar at the other end, 6D
// rows read as columns.
Eigen::Matrix3d euler_order_swapped(const std::string& name, const Eigen::VectorXd& v) {
  std::string other = name;
  if (name.rfind("pos_euler_", 0) == 0)
    for (std::size_t i = 10; i < other.size(); ++i) other[i] = static_cast<char>(other[i] ^ 32);
  return library_decode(other, v);
}
Eigen::Matrix3d scalar_at_the_other_end(const std::string& name, const Eigen::VectorXd& v) {
  if (name == "pos_quat_xyzw") return library_decode("pos_quat_wxyz", v);
  if (name == "pos_quat_wxyz") return library_decode("pos_quat_xyzw", v);
  return library_decode(name, v);
}
Eigen::Matrix3d rows_read_as_columns(const std::string& name, const Eigen::VectorXd& v) {
  if (name == "pos_rot6d_rows") return library_decode("pos_rot6d_cols", v);
  if (name == "pos_rot6d_cols") return library_decode("pos_rot6d_rows", v);
  return library_decode(name, v);
}

// How many of the hand-written vectors `decode` reads as another rotation than their layout's
// definition says (every matrix written out, not made by the library's axis_rotation).
int layouts_misread(DecodeFn decode) {
  // 90 degrees about x, y and z.
  Eigen::Matrix3d Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  Ry << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const double h = kPoseFormatPi / 2;
  int misread = 0;
  const auto expect = [&](const std::string& name, const Eigen::VectorXd& v,
                          const Eigen::Matrix3d& R) {
    const double gap = (decode(name, v) - R).norm();
    if (!(gap < 1e-15)) ++misread;  // NaN counts as misread
  };
  Eigen::VectorXd euler(6);
  euler << 0, 0, 0, h, h, 0;
  // Extrinsic "xyz" (a, b, c) is Rz(c) Ry(b) Rx(a); intrinsic "XYZ" is Rx(a) Ry(b) Rz(c).
  expect("pos_euler_xyz", euler, Ry * Rx);
  expect("pos_euler_XYZ", euler, Rx * Ry);
  euler << 0, 0, 0, 0, h, h;
  expect("pos_euler_zyx", euler, Rx * Ry);
  expect("pos_euler_ZXZ", euler, Rx * Rz);
  // 90 degrees about z: q = (0, 0, sin 45, cos 45) scalar last, (cos 45, 0, 0, sin 45) first.
  const double s = std::sqrt(0.5);
  Eigen::VectorXd q(7);
  q << 0, 0, 0, 0, 0, s, s;
  expect("pos_quat_xyzw", q, Rz);
  q << 0, 0, 0, s, 0, 0, s;
  expect("pos_quat_wxyz", q, Rz);
  Eigen::VectorXd r(6);
  r << 0, 0, 0, 0, h, 0;
  expect("pos_axis_angle", r, Ry);
  // The rows of Rz are (0, -1, 0) and (1, 0, 0); its columns (0, 1, 0) and (-1, 0, 0).
  Eigen::VectorXd six(9);
  six << 0, 0, 0, 0, -1, 0, 1, 0, 0;
  expect("pos_rot6d_rows", six, Rz);
  six << 0, 0, 0, 0, 1, 0, -1, 0, 0;
  expect("pos_rot6d_cols", six, Rz);
  return misread;
}

}  // namespace

// Also checked once against SciPy 1.10.1 (Debian bookworm's python3-scipy, not a dependency):
// Rotation.as_quat, as_rotvec and as_euler of all 24 sequences on 50 random rotations agree with
// encode_pose within 3e-15 (2026-12-05).
TEST_CASE("each_layout_means_what_its_name_says_on_hand_written_rotations", "[unit]") {
  CHECK(layouts_misread(library_decode) == 0);
  // Encoding puts the position first and picks w >= 0.
  Eigen::Matrix3d Rz;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const Eigen::VectorXd e = encode_pose(at(Rz), parse_pose_format("pos_quat_wxyz", "k"));
  CHECK(e(0) == 0.1);
  CHECK(e(3) > 0.0);
}

TEST_CASE("mutant_pose_layouts_misread_are_caught", "[unit]") {
  CHECK(layouts_misread(euler_order_swapped) == 4);
  CHECK(layouts_misread(scalar_at_the_other_end) == 2);
  CHECK(layouts_misread(rows_read_as_columns) == 2);
}

TEST_CASE("encode_then_decode_is_the_pose_on_every_layout_and_at_gimbal_lock", "[unit]") {
  std::mt19937_64 rng(7);
  std::vector<Eigen::Matrix3d> rotations;
  for (int i = 0; i < 200; ++i) rotations.push_back(random_rotation(rng).matrix());
  // Gimbal lock of every sequence: a middle angle of +-pi/2 or 0 and pi about each axis.
  for (int axis = 0; axis < 3; ++axis)
    for (double b : {kPoseFormatPi / 2, -kPoseFormatPi / 2, 0.0, kPoseFormatPi})
      for (int other = 0; other < 3; ++other)
        rotations.push_back(axis_rotation(other, 0.7) * axis_rotation(axis, b) *
                            axis_rotation((other + 1) % 3, -0.4));
  rotations.push_back(Eigen::Matrix3d::Identity());
  for (const PoseFormat& f : every_pose_format()) {
    double worst = 0.0;
    for (const Eigen::Matrix3d& R : rotations) {
      const double gap = pose_gap(decode_pose(encode_pose(at(R), f), f, "v"), at(R));
      worst = std::isnan(gap) ? gap : std::max(worst, gap);
      if (std::isnan(worst)) break;
    }
    INFO(f.name());
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("euler_angles_lie_in_the_ranges_scipy_documents", "[unit]") {
  std::mt19937_64 rng(8);
  for (const PoseFormat& f : every_pose_format()) {
    if (f.kind != PoseFormat::Kind::pos_euler) continue;
    const bool proper = f.axes[0] == f.axes[2];
    for (int i = 0; i < 100; ++i) {
      const Eigen::VectorXd v = encode_pose(at(random_rotation(rng).matrix()), f);
      INFO(f.name() << " " << v.transpose());
      CHECK(std::abs(v(3)) <= kPoseFormatPi);
      CHECK(std::abs(v(5)) <= kPoseFormatPi);
      if (proper) {
        CHECK(v(4) >= 0.0);
        CHECK(v(4) <= kPoseFormatPi);
      } else {
        CHECK(std::abs(v(4)) <= kPoseFormatPi / 2);
      }
    }
  }
}

TEST_CASE("a_vector_that_contradicts_its_layout_is_refused_with_its_numbers", "[unit]") {
  Eigen::VectorXd q(7);
  q << 0, 0, 0, 0.1, 0.2, 0.3, 1.2;  // norm 1.257
  HC_CHECK_THROWS(
      decode_pose(q, parse_pose_format("pos_quat_xyzw", "k"), "a[3]"), InvalidArgument,
      Catch::Contains("a[3] =") && Catch::Contains("norm 1.257") && Catch::Contains("normalize"));
  Eigen::VectorXd six(9);
  six << 0, 0, 0, 1, 0, 0, 0.3, 1, 0;  // dot product 0.3
  HC_CHECK_THROWS(decode_pose(six, parse_pose_format("pos_rot6d_rows", "k"), "a"), InvalidArgument,
                  Catch::Contains("rows are not orthonormal") &&
                      Catch::Contains("dot product 0.3") && Catch::Contains("Gram-Schmidt"));
  Eigen::VectorXd seven(7);
  seven << 0, 0, 0, 0, 0, 0, 1;
  HC_CHECK_THROWS(decode_pose(seven, parse_pose_format("pos_euler_xyz", "k"), "a"), InvalidArgument,
                  Catch::Contains("has 7 numbers") && Catch::Contains("pos_euler_xyz has 6"));
  seven(6) = std::nan("");
  HC_CHECK_THROWS(decode_pose(seven, parse_pose_format("pos_quat_wxyz", "k"), "a"), InvalidArgument,
                  Catch::Contains("non-finite"));
  Eigen::VectorXd m = Eigen::VectorXd::Zero(16);
  m(0) = m(5) = m(10) = 1.0;  // last row (0, 0, 0, 0)
  HC_CHECK_THROWS(decode_pose(m, parse_pose_format("matrix", "k"), "a"), InvalidArgument,
                  Catch::Contains("last row"));
  // Within the tolerance: a float32 policy's quaternion is read, normalized.
  q << 0, 0, 0, 0, 0, 0, 1.0 + 1e-6;
  CHECK(decode_pose(q, parse_pose_format("pos_quat_xyzw", "k"), "a").rotation().matrix() ==
        Eigen::Matrix3d::Identity());
}

TEST_CASE("an_unknown_pose_format_names_the_keyword_the_value_and_the_formats", "[unit]") {
  HC_CHECK_THROWS(parse_pose_format("quat", "action_format"), InvalidArgument,
                  Catch::Contains("action_format='quat'") && Catch::Contains("pos_quat_xyzw") &&
                      Catch::Contains("pos_euler_<axes>"));
  HC_CHECK_THROWS(
      parse_pose_format("pos_euler_xxy", "state_format"), InvalidArgument,
      Catch::Contains("state_format='pos_euler_xxy'") && Catch::Contains("twice in a row"));
  HC_CHECK_THROWS(parse_pose_format("pos_euler_xYz", "k"), InvalidArgument,
                  Catch::Contains("mix lowercase and uppercase"));
  HC_CHECK_THROWS(parse_pose_format("pos_euler_xyw", "k"), InvalidArgument,
                  Catch::Contains("'w' is not an axis"));
  HC_CHECK_THROWS(parse_pose_format("pos_euler_xy", "k"), InvalidArgument,
                  Catch::Contains("not three letters"));
}
