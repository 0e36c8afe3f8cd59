#include "handcentric/props/prefetch.hpp"

#include <algorithm>

namespace handcentric::props {
namespace {

// The innermost check's passes on this thread (a check may run inside another's case).
thread_local detail::PrefetchPasses* current_passes = nullptr;

}  // namespace

bool prefetching() {
  return current_passes != nullptr && current_passes->prefetching_;
}

namespace detail {

void enlist(Prefetcher& prefetcher) {
  if (current_passes == nullptr) return;
  ++current_passes->recorded_;
  auto& enlisted = current_passes->enlisted_;
  if (std::find(enlisted.begin(), enlisted.end(), &prefetcher) == enlisted.end())
    enlisted.push_back(&prefetcher);
}

PrefetchPasses::PrefetchPasses() : outer_(current_passes) {
  current_passes = this;
}

PrefetchPasses::~PrefetchPasses() {
  current_passes = outer_;
}

void PrefetchPasses::pass(const std::function<void()>& body) {
  prefetching_ = true;
  try {
    body();
  } catch (...) {
    prefetching_ = false;
    throw;
  }
  prefetching_ = false;
}

std::size_t PrefetchPasses::flush() {
  std::vector<Prefetcher*> enlisted;
  enlisted.swap(enlisted_);
  recorded_ = 0;
  std::size_t evaluated = 0;
  for (Prefetcher* p : enlisted) evaluated += p->flush();
  return evaluated;
}

}  // namespace detail
}  // namespace handcentric::props
