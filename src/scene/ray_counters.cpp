#include "scene/ray_counters.h"

#include "bdptref/scene.h"

#include <deque>
#include <mutex>

namespace bdptref {

namespace {
// A deque never moves its elements, so a thread's reference stays valid as others register.
std::mutex& registryMutex() {
    static std::mutex m;
    return m;
}
std::deque<ThreadRayCounters>& registry() {
    static auto* slots = new std::deque<ThreadRayCounters>();  // leaked on purpose: outlives every thread
    return *slots;
}
}  // namespace

ThreadRayCounters& registerThreadRayCounters() {
    std::lock_guard<std::mutex> lock(registryMutex());
    tThreadRayCounters = &registry().emplace_back();
    return *tThreadRayCounters;
}

RayCounts rayCountsSoFar() {
    std::lock_guard<std::mutex> lock(registryMutex());
    RayCounts total;
    for (const ThreadRayCounters& c : registry()) {
        total.extension += c.extension.load(std::memory_order_relaxed);
        total.shadow += c.shadow.load(std::memory_order_relaxed);
    }
    return total;
}

}  // namespace bdptref
