#include "handcentric/policy/normalizer.hpp"

#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::policy {

namespace {

void require_length(Eigen::Index rows, Eigen::Index dimension) {
  if (rows != dimension) {
    throw InvalidArgument("Normalizer: vectors of length " + std::to_string(rows) + ", expected " +
                          std::to_string(dimension));
  }
}

}  // namespace

Normalizer::Normalizer(Eigen::Index dimension)
    : Normalizer(Eigen::VectorXd::Zero(dimension), Eigen::VectorXd::Ones(dimension)) {}

Normalizer::Normalizer(Eigen::VectorXd mean, Eigen::VectorXd scale, Eigen::VectorXd active)
    : mean_(std::move(mean)), scale_(std::move(scale)), active_(std::move(active)) {
  if (active_.size() == 0) active_ = Eigen::VectorXd::Ones(mean_.size());
  if (active_.size() != mean_.size()) {
    throw InvalidArgument("Normalizer: " + std::to_string(active_.size()) + " activity flags for " +
                          std::to_string(mean_.size()) + " dimensions; give one per dimension");
  }
  for (Eigen::Index i = 0; i < active_.size(); ++i) {
    if (active_[i] != 0.0 && active_[i] != 1.0) {
      throw InvalidArgument("Normalizer: activity flag " + std::to_string(i) + " is " +
                            format_number(active_[i]) + ": use 0 (constant dimension) or 1");
    }
  }
  if (mean_.size() != scale_.size()) {
    throw InvalidArgument("Normalizer: " + std::to_string(mean_.size()) + " means but " +
                          std::to_string(scale_.size()) +
                          " scales; give one of each per dimension");
  }
  for (Eigen::Index i = 0; i < mean_.size(); ++i) {
    if (!std::isfinite(mean_[i]) || !std::isfinite(scale_[i]) || !(scale_[i] > 0.0)) {
      throw InvalidArgument("Normalizer: dimension " + std::to_string(i) + " has mean " +
                            format_number(mean_[i]) + " and scale " + format_number(scale_[i]) +
                            ": means must be finite and scales finite and positive");
    }
  }
  mean_f_ = mean_.cast<float>();
  scale_f_ = scale_.cast<float>();
  inv_scale_f_ = scale_.cwiseInverse().cast<float>();
  active_f_ = active_.cast<float>();
}

Normalizer Normalizer::fit(const Eigen::MatrixXd& data) {
  if (data.cols() == 0)
    throw InvalidArgument("Normalizer::fit: no samples; give at least one column");
  if (!data.allFinite()) throw InvalidArgument("Normalizer::fit: the data has a non-finite entry");
  const Eigen::VectorXd mean = data.rowwise().mean();
  Eigen::VectorXd scale(data.rows()), active(data.rows());
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    const double std_dev = std::sqrt((data.row(i).array() - mean[i]).square().mean());
    const bool constant = std_dev < 1e-8 * (1.0 + std::abs(mean[i]));
    scale[i] = constant ? 1.0 : std_dev;
    active[i] = constant ? 0.0 : 1.0;
  }
  return Normalizer(mean, scale, active);
}

void Normalizer::normalize(Eigen::Ref<Eigen::MatrixXf> columns) const {
  require_length(columns.rows(), dimension());
  // One pass, each value rounded after the subtraction and after the product.
  columns.array() = (columns.array().colwise() - mean_f_.array()).colwise() * inv_scale_f_.array();
}

void Normalizer::normalize(const Eigen::Ref<const Eigen::MatrixXf>& columns,
                           Eigen::MatrixXf& out) const {
  require_length(columns.rows(), dimension());
  out.resize(columns.rows(), columns.cols());
  out.array() = (columns.array().colwise() - mean_f_.array()).colwise() * inv_scale_f_.array();
}

void Normalizer::normalize(const Eigen::Ref<const Eigen::MatrixXf>& set,
                           std::span<const Eigen::Index> picked, Eigen::MatrixXf& out) const {
  require_length(set.rows(), dimension());
  for (const Eigen::Index i : picked) {
    if (i < 0 || i >= set.cols()) {
      throw InvalidArgument("Normalizer: column " + std::to_string(i) + " picked from a set of " +
                            std::to_string(set.cols()) + " columns");
    }
  }
  out.resize(set.rows(), static_cast<Eigen::Index>(picked.size()));
  for (std::size_t j = 0; j < picked.size(); ++j) {
    out.col(static_cast<Eigen::Index>(j)).array() =
        (set.col(picked[j]).array() - mean_f_.array()) * inv_scale_f_.array();
  }
}

void Normalizer::denormalize(Eigen::Ref<Eigen::MatrixXf> columns) const {
  require_length(columns.rows(), dimension());
  columns.array().colwise() *= scale_f_.array();
  columns.colwise() += mean_f_;
}

}  // namespace handcentric::policy
