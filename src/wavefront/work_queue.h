// A fixed-capacity queue like a GPU buffer plus an atomic append counter. Producers append from
// parallel launches with fetch_add (the slot an entry gets depends on the threads, so nothing
// downstream may depend on it: entries carry the index of their path or connection). A producer
// never appends more than free() entries per launch chunk (docs/wavefront.md, "Flushes").
#pragma once

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace bdptref {

template <class T>
class WorkQueue {
public:
    void reset(uint32_t capacity) {
        items_.assign(capacity, T{});
        count_.store(0);
    }
    uint32_t capacity() const { return uint32_t(items_.size()); }
    uint32_t size() const { return count_.load(std::memory_order_relaxed); }
    uint32_t free() const { return capacity() - size(); }
    bool empty() const { return size() == 0; }
    void clear() { count_.store(0); }
    // Thread-safe append (the emulated atomicAdd on the queue counter).
    void push(const T& value) {
        const uint32_t slot = count_.fetch_add(1, std::memory_order_relaxed);
        if (slot >= items_.size()) throw std::logic_error("wavefront queue overflow (a producer ignored free())");
        items_[slot] = value;
    }
    const T& operator[](uint32_t i) const { return items_[i]; }
    T& operator[](uint32_t i) { return items_[i]; }
    void swap(WorkQueue& other) {
        items_.swap(other.items_);
        const uint32_t a = count_.load(), b = other.count_.load();
        count_.store(b);
        other.count_.store(a);
    }

private:
    std::vector<T> items_;
    std::atomic<uint32_t> count_{0};
};

}  // namespace bdptref
