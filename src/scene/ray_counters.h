// Per-thread ray counters behind rayCountsSoFar() (scene.h). Each thread increments its own
// slot without a lock or an atomic read-modify-write, so counting costs a few cycles per ray and
// does not contend between threads (see src/scene/ray_counters.cpp).
#pragma once

#include <atomic>
#include <cstdint>

namespace bdptref {

struct ThreadRayCounters {
    std::atomic<uint64_t> extension{0};
    std::atomic<uint64_t> shadow{0};
};

// This thread's slot (registered on first use, never freed, so totals survive thread exit).
ThreadRayCounters& threadRayCounters();

// Only the owning thread writes its slot: a relaxed load + store is an exact increment.
inline void countRay(std::atomic<uint64_t>& c) { c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }

}  // namespace bdptref
