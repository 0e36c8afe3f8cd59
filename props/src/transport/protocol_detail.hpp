#pragma once
// Internal: the number writers and answer readers of plugin_protocol.cpp that policy_wire.cpp
// shares (defined in plugin_protocol.cpp).
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "../wire_arrays.hpp"

namespace handcentric::props::protocol_detail {

/// The shortest text that reads back as the same double.
void append_number(std::string& out, double value);
/// A vector as JSON numbers or an encoded [n] array.
void append_vector(std::string& out, const Eigen::VectorXd& v, NumberEncoding encoding);
/// A JSON string literal of a name.
void append_name(std::string& out, const std::string& name);
/// "<who> answered request <id>".
std::string reply_to(const std::string& who, int id);
/// PluginError naming `field` and the index of the first non-finite value.
void require_finite(const double* values, std::size_t count, const std::string& field,
                    const std::string& answered);
/// An encoded array of finite float64 numbers of `rank` dimensions (`form` names the shape
/// expected, for the message).
wire::Array read_encoded(const nlohmann::json& value, const std::string& field, std::size_t rank,
                         const std::string& form, const std::string& answered);
/// A JSON list of finite numbers, or an encoded [n] array.
Eigen::VectorXd read_numbers(const nlohmann::json& value, const std::string& field,
                             const std::string& answered);

/// The pose of 16 row-major numbers `v`, the k-th of `field`: PluginError unless its last row is
/// 0 0 0 1 and its block a rotation within kOutputPoseTolerance.
RigidTransform pose_from(const double* v, std::size_t k, const std::string& answered,
                         const std::string& field);

}  // namespace handcentric::props::protocol_detail
