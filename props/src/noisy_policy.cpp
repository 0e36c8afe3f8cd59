#include "handcentric/props/noisy_policy.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/scene_key.hpp"

namespace handcentric::props {

std::vector<std::vector<RigidTransform>> NoisyPolicy::act_fresh(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  std::vector<std::vector<RigidTransform>> out;
  out.reserve(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i)
    out.push_back(act(*observations[i], *noises[i]));
  return out;
}

SeededPolicy::SeededPolicy(std::shared_ptr<const ChunkPolicy> policy) : policy_(std::move(policy)) {
  if (!policy_) throw InvalidArgument("SeededPolicy needs a policy, got null");
}

std::vector<RigidTransform> SeededPolicy::act(const Scene& observation,
                                              const Eigen::VectorXd& noise) const {
  // FNV-1a over the noise's bytes: the same vector, the same seed.
  std::uint64_t seed = 1469598103934665603ULL;
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    std::uint64_t bits = 0;
    const double x = noise(i);
    std::memcpy(&bits, &x, sizeof(bits));
    for (int b = 0; b < 8; ++b) seed = (seed ^ ((bits >> (8 * b)) & 0xffU)) * 1099511628211ULL;
  }
  return policy_->act(observation, seed);
}

namespace {

/// FNV-1a over `size` bytes, continuing from `hash`.
std::uint64_t fnv1a(std::uint64_t hash, const void* bytes, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(bytes);
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ p[i]) * 1099511628211ULL;
  return hash;
}

}  // namespace

std::uint64_t case_noise_seed(std::uint64_t seed, const Scene& scene, const RigidTransform* g) {
  std::uint64_t hash = fnv1a(1469598103934665603ULL, &seed, sizeof(seed));
  // The scene's bytes as its cache key has them, but for the held arrays, which the key names by
  // address: their values here, so that the same case gets the same noise in every run.
  Scene without_held = scene;
  without_held.held.clear();
  const std::string key = detail::scene_key(without_held, false);
  hash = fnv1a(hash, key.data(), key.size());
  for (const auto& [name, array] : scene.held) {
    hash = fnv1a(hash, name.data(), name.size());
    hash = fnv1a(hash, array->values.data(), sizeof(double) * array->values.size());
  }
  if (g == nullptr) return hash;
  const Eigen::Matrix4d m = g->matrix();
  return fnv1a(hash, m.data(), sizeof(double) * 16);
}

Eigen::VectorXd fixed_noise(Eigen::Index n, std::uint64_t seed) {
  // The first n normals of one stream: cache a long prefix per thread (seeding a Mersenne
  // twister costs more than the checks that use it).
  thread_local std::uint64_t cached_seed = 0;
  thread_local Eigen::VectorXd cached;
  if (cached.size() < n || cached_seed != seed) {
    std::mt19937_64 rng(seed);
    cached.resize(std::max<Eigen::Index>(n, 256));
    for (Eigen::Index i = 0; i < cached.size(); ++i) cached(i) = standard_normal(rng);
    cached_seed = seed;
  }
  return cached.head(n);
}

}  // namespace handcentric::props
