#pragma once
// Where `eval` and `render` get the policy they roll out: a trained model file (--model) or a
// scripted policy of the sim by name (--policy expert|straight|hold).
#include <memory>
#include <string>

#include "handcentric/core/chunk_policy.hpp"

namespace handcentric::apps {

/// The model in `model_path` when it is not empty, else the scripted policy `scripted_name`.
/// Throws a typed error naming the file or the name when neither can be had.
std::unique_ptr<ChunkPolicy> load_chunk_policy(const std::string& model_path,
                                               const std::string& scripted_name);

}  // namespace handcentric::apps
