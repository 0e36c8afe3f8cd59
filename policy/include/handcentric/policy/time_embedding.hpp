#pragma once
// The network's view of the flow / diffusion time t in [0, 1].
//
//   dimension 0 : t itself (one feature)
//   dimension 2m: [sin(w_0 t), cos(w_0 t), ..., sin(w_{m-1} t), cos(w_{m-1} t)],
//                 w_i = 2^(i * 10 / max(m - 1, 1)) (frequencies from 1 to 1024 rad per unit t)
#include <Eigen/Core>

namespace handcentric::policy {

/// How many features time_features() writes for `dimension` (1 for 0, else `dimension`).
int time_feature_count(int dimension);

/// Writes the features of t into `out` (length time_feature_count(dimension)).
void time_features(double t, int dimension, Eigen::Ref<Eigen::VectorXf> out);

}  // namespace handcentric::policy
