#pragma once
// The 3D task's image policies (PolicyConfig::observation = image): the hand camera
// (sim/insert3d/camera.hpp, one camera model with the audit's, core/camera.hpp) as the policy's
// ImageSource (policy/image_source.hpp), and loading a 3D model with the input it was trained on.
//
// Insert3dHandCamera renders an observation from its eye-in-hand points: the slot opening's four
// corners in the hand frame fix hand_T_slot (sim/insert3d/rollout.hpp), and the camera renders
// the block and the blade there. Only hand-frame points enter, so g * scene gets the same image
// bit for bit and a hand-centric image policy is SE(3)-equivariant whatever its encoder learned
// (Theorem 1 of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior Cloning"). Any
// four points are rendered (the audit's random scenes too): degenerate ones get a fixed frame.
//
// With `floor`, the camera also sees a table: the world's half-space z <= table_z, placed through
// T_0, as a real cell holds it still while g moves the hand and slot. The image then changes with
// every g that moves the table in the hand's view (everything but rotations about z and x-y
// translations), and `handcentric audit --model M --floor` shows the hand-centric image policy
// lose those groups: Theorem 1 needs every pixel to move with the scene.
#include <memory>
#include <string>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/policy/image_source.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/sim/insert3d/camera.hpp"

namespace handcentric::experiments {

/// depth: 1 channel, the camera's depth (cm). rgbd: red, green, blue in [0, 1], then depth.
enum class Insert3dImageChannels { depth, rgbd };

/// "depth", "rgbd".
std::string to_string(Insert3dImageChannels channels);
/// Throws InvalidArgument naming the value and the valid names.
Insert3dImageChannels parse_insert3d_image_channels(const std::string& name);

struct Insert3dHandCameraOptions {
  sim::insert3d::DepthCamera camera;  ///< 32 x 24, 70 deg, 60 cm, the task's mount
  Insert3dImageChannels channels = Insert3dImageChannels::depth;
  bool floor = false;
  double table_z = 0.0;  ///< the table's top in the world (cm)
};

class Insert3dHandCamera final : public policy::ImageSource {
 public:
  /// Throws InvalidArgument for a bad camera.
  explicit Insert3dHandCamera(Insert3dHandCameraOptions options = {});
  std::string name() const override;
  policy::ImageShape shape() const override;
  /// Throws InvalidScene unless the observation has exactly four eye-in-hand points.
  void render(const Scene& observation, Eigen::Ref<Eigen::VectorXd> image) const override;
  /// The camera image itself (depth and colour) of an observation, for pictures.
  CameraImage render_image(const Scene& observation) const;
  const Insert3dHandCameraOptions& options() const { return options_; }

 private:
  Insert3dHandCameraOptions options_;
};

/// The hand camera an image config was trained with (its channels and size, no floor).
/// Throws InvalidArgument for a config that is not an image model of the 3D task.
std::shared_ptr<const Insert3dHandCamera> insert3d_camera_of(const policy::PolicyConfig& config,
                                                             bool floor = false);

/// A trained 3D model as the rollouts run it: an image model looking through its hand camera
/// (with the table when `floor`), a key-point model behind SlotKeyPointPolicy
/// (insert3d_key_points.hpp), the input each was trained on.
std::shared_ptr<const ChunkPolicy> insert3d_model_policy(
    std::shared_ptr<const policy::LearnedPolicy> model);

/// `model` given the camera it needs: an image model of the 3D task gets its hand camera (and
/// the table with `floor`), any other model is returned as it is.
policy::LearnedPolicy with_task_camera(const policy::LearnedPolicy& model, bool floor = false);

}  // namespace handcentric::experiments
