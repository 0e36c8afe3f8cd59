#pragma once
// PoseFormat: how a shipped policy writes one pose world_T_hand as a flat vector, and the one
// definition of each layout (the audit's action_format= / state_format=, the plug-in helper's
// handcentric_plugin.formats, which its tests hold to this one both ways).
//
//   name                 width  numbers
//   matrix               16     the 4x4 matrix, row-major
//   pos_quat_xyzw        7      p, then q = (x, y, z, w)   (SciPy's as_quat, robosuite, ROS)
//   pos_quat_wxyz        7      p, then q = (w, x, y, z)   (PyTorch3D, MuJoCo)
//   pos_axis_angle       6      p, then the rotation vector phi v, phi in [0, pi] (robomimic)
//   pos_rot6d_rows       9      p, then the first two ROWS of R (UMI, PyTorch3D, LeRobot)
//   pos_rot6d_cols       9      p, then the first two COLUMNS of R (Zhou et al. 2019)
//   pos_euler_<axes>     6      p, then three angles about <axes> as SciPy spells them: three
//                               of x, y, z, no axis twice in a row; lowercase extrinsic (about
//                               the fixed axes), uppercase intrinsic (about the moving ones):
//                               "xyz" is R = Rz(c) Ry(b) Rx(a), "XYZ" is R = Rx(a) Ry(b) Rz(c)
//
// Encoding picks one vector per pose: the quaternion with w >= 0, the rotation vector of
// so3::log, Euler angles with the first and last in (-pi, pi] and the middle in [-pi/2, pi/2]
// (three different axes) or [0, pi] (first axis repeated), the third set to 0 at gimbal lock
// (SciPy's ranges and its choice at gimbal lock). Decoding takes any vector of a layout whose
// numbers are what the layout says, within kLayoutTolerance, and returns the rotation they
// name: a quaternion normalized, 6D vectors orthonormalized (Gram-Schmidt, as PyTorch3D's
// rotation_6d_to_matrix and UMI's rot6d_to_mat do).
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric {

struct PoseFormat {
  enum class Kind {
    matrix,
    pos_quat_xyzw,
    pos_quat_wxyz,
    pos_axis_angle,
    pos_rot6d_rows,
    pos_rot6d_cols,
    pos_euler
  };
  Kind kind = Kind::matrix;
  /// pos_euler: the axes (0 = x, 1 = y, 2 = z) in the order the angles are given.
  std::array<int, 3> axes = {0, 1, 2};
  /// pos_euler: about the moving axes (uppercase) or the fixed ones (lowercase).
  bool intrinsic = false;

  /// The name as parse_pose_format takes it ("pos_euler_XYZ").
  std::string name() const;
  /// The numbers per pose.
  int width() const;
  bool operator==(const PoseFormat& other) const {
    return kind == other.kind &&
           (kind != Kind::pos_euler || (axes == other.axes && intrinsic == other.intrinsic));
  }
};

/// How far a decoded vector's numbers may be from what its layout says (a quaternion's norm
/// from 1; 6D vectors' norms from 1 and their dot product from 0) before the layout is taken as
/// contradicted: loose enough for a policy's float32 or bfloat16 output (bfloat16's spacing at
/// 1 is 2^-7), far below what a misread layout gives (an axis-angle read as a quaternion).
inline constexpr double kLayoutTolerance = 1e-2;

/// The format named `text`; InvalidArgument naming `keyword`, the value and the names there are.
PoseFormat parse_pose_format(const std::string& text, const std::string& keyword);

/// Every name parse_pose_format takes, pos_euler_<axes> spelled as its pattern.
std::vector<std::string> pose_format_names();

/// The vector of `pose` in `format` (format.width() numbers).
Eigen::VectorXd encode_pose(const RigidTransform& pose, const PoseFormat& format);

/// The pose `vector` names in `format`. `what` names the vector in errors ("the chunk returned
/// by policy f [2][5]"). Throws InvalidArgument for a wrong length, a non-finite number or a
/// vector that contradicts its layout (message: the numbers, what is wrong, the fix), and for
/// format matrix a last row other than (0, 0, 0, 1); a matrix's 3x3 block is taken as given, not
/// checked for orthonormality (the audit measures how far a returned matrix is from g T).
RigidTransform decode_pose(const Eigen::Ref<const Eigen::VectorXd>& vector,
                           const PoseFormat& format, const std::string& what);

/// The rotation about axis `axis` (0 = x, 1 = y, 2 = z) by `angle` radians.
Eigen::Matrix3d axis_rotation(int axis, double angle);

}  // namespace handcentric
