#pragma once
// Scenes as bytes: the key under which a batched map caches an answer, and the shape that scenes
// must share to be stacked in one batch (transport/batch.hpp; the preflight picks its
// observations by it too).
#include <string>

#include "handcentric/core/scene.hpp"

namespace handcentric::props {

namespace detail {

/// The bytes of a scene's observation (its chunk too when `with_chunk`): a cache key.
std::string scene_key(const Scene& scene, bool with_chunk);

/// What must agree for scenes to be stacked in one batch: the history and chunk lengths and the
/// numbers of points (extra poses and scalars are the audit's, the same for every scene).
std::string shape_key(const Scene& scene, bool with_chunk);

}  // namespace detail

}  // namespace handcentric::props
