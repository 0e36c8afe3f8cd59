#pragma once
// Per-dimension normalization from training statistics: x_n = (x - mean) / scale.
//
// It is a CONSTANT affine map, fixed once from the training set. Applied to an invariant vector
// (a hand-centric action or observation) it gives an invariant vector, so it cannot break the
// invariance that Theorem 1 rests on; only a map that looked at the world pose could.
// (tests/policy: normalized_hand_centric_vectors_stay_se3_invariant.)
#include <span>

#include <Eigen/Core>

namespace handcentric::policy {

class Normalizer {
 public:
  /// The identity map for `dimension` numbers.
  explicit Normalizer(Eigen::Index dimension = 0);
  /// Validating: throws InvalidArgument for different lengths, a non-finite mean, a scale that
  /// is not finite and positive, or an `active` entry other than 0 or 1 (empty: all 1).
  Normalizer(Eigen::VectorXd mean, Eigen::VectorXd scale, Eigen::VectorXd active = {});

  /// Mean and standard deviation of each row of `data` (one sample per column). A row whose
  /// standard deviation is below 1e-8 * (1 + |mean|) (a constant, e.g. z in a planar task) gets
  /// scale 1, so it is only shifted, and active 0. Throws InvalidArgument for no columns or a
  /// non-finite entry.
  static Normalizer fit(const Eigen::MatrixXd& data);

  Eigen::Index dimension() const { return mean_.size(); }
  const Eigen::VectorXd& mean() const { return mean_; }
  const Eigen::VectorXd& scale() const { return scale_; }
  /// 1 for a dimension that varies in the training data, 0 for a constant one. The heads put no
  /// noise and no velocity there (a planar task's z and tilt stay exactly at their constant).
  const Eigen::VectorXd& active() const { return active_; }
  const Eigen::VectorXf& active_float() const { return active_f_; }
  /// The mean and 1 / scale in float, as normalize() applies them: (x - mean) * inv_scale.
  const Eigen::VectorXf& mean_float() const { return mean_f_; }
  const Eigen::VectorXf& inv_scale_float() const { return inv_scale_f_; }

  /// In place, column by column: x <- (x - mean) / scale.
  void normalize(Eigen::Ref<Eigen::MatrixXf> columns) const;
  /// out = the columns normalized, in one pass (out resized to their shape): the bits of a copy
  /// normalized in place, without the pass of the copy (a training batch of images is tens of MB).
  void normalize(const Eigen::Ref<const Eigen::MatrixXf>& columns, Eigen::MatrixXf& out) const;
  /// out = columns `picked` of `set` normalized (out.col(j) from set.col(picked[j])), in one
  /// pass: the bits of normalize() on those columns copied out, without the copy (a training
  /// step's draw from the training set). Every index must be a column of `set`.
  void normalize(const Eigen::Ref<const Eigen::MatrixXf>& set, std::span<const Eigen::Index> picked,
                 Eigen::MatrixXf& out) const;
  /// In place: x <- mean + scale * x.
  void denormalize(Eigen::Ref<Eigen::MatrixXf> columns) const;

 private:
  Eigen::VectorXd mean_, scale_, active_;
  Eigen::VectorXf mean_f_, inv_scale_f_, scale_f_, active_f_;
};

}  // namespace handcentric::policy
