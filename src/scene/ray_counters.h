// Per-thread ray counters behind rayCountsSoFar() (scene.h). Each thread increments its own
// slot without a lock or an atomic read-modify-write, so counting costs a few cycles per ray and
// does not contend between threads (see src/scene/ray_counters.cpp).
#pragma once

#include <atomic>
#include <cstdint>

namespace bdptref {

// One cache line per thread: slots of 16 bytes sat side by side in the registry, so two threads
// counting rays wrote to the same line on every ray (false sharing): light tracing with 2 threads
// spent 1.6x the CPU time of 1 thread, a quarter of it in Scene::intersect and Scene::visible.
struct alignas(64) ThreadRayCounters {
    std::atomic<uint64_t> extension{0};
    std::atomic<uint64_t> shadow{0};
};

// This thread's slot (registered on first use, never freed, so totals survive thread exit).
// Inline: read on every ray; only the first use of a thread takes the registry's lock
// (registerThreadRayCounters).
ThreadRayCounters& registerThreadRayCounters();
inline thread_local ThreadRayCounters* tThreadRayCounters = nullptr;
inline ThreadRayCounters& threadRayCounters() {
    ThreadRayCounters* mine = tThreadRayCounters;
    return mine ? *mine : registerThreadRayCounters();
}

// Only the owning thread writes its slot: a relaxed load + store is an exact increment.
inline void countRay(std::atomic<uint64_t>& c) { c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }

}  // namespace bdptref
