#include "policy_source.hpp"

#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/sim/policies.hpp"

namespace handcentric::apps {

std::unique_ptr<ChunkPolicy> load_chunk_policy(const std::string& model_path,
                                               const std::string& scripted_name) {
  if (!model_path.empty()) return std::make_unique<policy::LearnedPolicy>(policy::load_model(model_path));
  return sim::make_scripted_policy(scripted_name);
}

}  // namespace handcentric::apps
