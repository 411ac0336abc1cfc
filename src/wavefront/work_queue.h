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
    // Thread-safe append of `count` entries at once: one fetch_add for a whole block (ChunkAppender).
    void pushBlock(const T* values, uint32_t count) {
        if (count == 0) return;
        const uint32_t slot = count_.fetch_add(count, std::memory_order_relaxed);
        if (uint64_t(slot) + count > items_.size()) throw std::logic_error("wavefront queue overflow (a producer ignored free())");
        for (uint32_t k = 0; k < count; ++k) items_[slot + k] = values[k];
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

// The appends of one chunk of a launch, staged and written as blocks. With one fetch_add per
// entry, two threads appending to the same queue fought over its counter's cache line (and the
// entries they wrote interleaved, so the next launch's threads shared the lines of their per-
// entry state): the wavefront BDPT took 2.6x the megakernel's CPU time on 2 threads.
// Call flush() at the end of the chunk.
template <class T>
class ChunkAppender {
public:
    explicit ChunkAppender(WorkQueue<T>& queue) : queue_(queue) {}
    void push(const T& value) {
        buffer_[count_++] = value;
        if (count_ == kBlock) flush();
    }
    void flush() {
        queue_.pushBlock(buffer_, count_);
        count_ = 0;
    }

private:
    static constexpr uint32_t kBlock = 64;
    WorkQueue<T>& queue_;
    T buffer_[kBlock];
    uint32_t count_ = 0;
};

}  // namespace bdptref
