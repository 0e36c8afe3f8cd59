#pragma once
// ImageSource: the camera an image policy looks through (PolicyConfig::observation = image).
// It renders a policy observation (a Scene: the hand's poses and the task's points) into the
// image the policy's ConvEncoder reads. The task supplies it (experiments/insert3d_image.hpp for
// the 3D task's hand camera): the policy library knows no task geometry.
//
// An image policy's observation vector is
//
//   [ representation.encode_observation(the scene without its points) ; the image ]
//
// the proprioception (the hand's poses) in the representation's frame, eq. (3) for hand_centric,
// followed by the image, channels-first as PyTorch stores it. An eye-in-hand camera renders the
// same image for g * scene as for the scene, so with hand_centric the whole vector is invariant
// and the policy SE(3)-equivariant whatever the encoder learned (Theorem 1; Sec. 3.2 of
// "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior Cloning").
#include <Eigen/Core>
#include <string>

#include "handcentric/core/representation.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/policy/conv2d.hpp"

namespace handcentric::policy {

class ImageSource {
 public:
  virtual ~ImageSource() = default;
  /// Names the camera in messages, e.g. "insert3d hand camera (depth, 32 x 24)".
  virtual std::string name() const = 0;
  /// 1 channel (depth) or 4 (red, green, blue, depth).
  virtual ImageShape shape() const = 0;
  /// The image of `observation` (shape().size() numbers, channels-first, width fastest) into
  /// `image`. Throws InvalidScene for an observation it cannot render.
  virtual void render(const Scene& observation, Eigen::Ref<Eigen::VectorXd> image) const = 0;
};

/// The observation vector above. Throws InvalidScene for an invalid observation.
Eigen::VectorXd encode_image_observation(const Representation& representation,
                                         const ImageSource& camera, const Scene& observation);

}  // namespace handcentric::policy
