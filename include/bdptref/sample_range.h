// Which pixel-sample indices an image holds. Sample k of a pixel is a pure function of (scene,
// settings, seed, pixel, k) (docs/contracts.md, contract 2), so an image is described exactly by the set of
// indices it accumulated: [0, spp) for a plain render, A..B-1 for `render --sample-range A:B`, a
// union for `merge`. Text form: "A:B" ranges joined by ',' (e.g. "0:32,48:64").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

struct SampleRange {
    uint64_t begin = 0, end = 0;  // [begin, end)
    uint64_t size() const { return end - begin; }
    bool operator==(const SampleRange& o) const { return begin == o.begin && end == o.end; }
};

// A sorted union of disjoint, non-adjacent ranges (adjacent ones are joined).
class SampleRanges {
public:
    SampleRanges() = default;
    // Adds [begin, end); returns false (and changes nothing) if it overlaps a range already held.
    bool add(SampleRange r);
    const std::vector<SampleRange>& ranges() const { return ranges_; }
    bool empty() const { return ranges_.empty(); }
    bool contiguous() const { return ranges_.size() <= 1; }
    uint64_t total() const;
    uint64_t firstIndex() const { return ranges_.empty() ? 0 : ranges_.front().begin; }  // not begin(): not an iterator range
    uint64_t endIndex() const { return ranges_.empty() ? 0 : ranges_.back().end; }
    std::string text() const;  // "" when empty
    bool operator==(const SampleRanges& o) const { return ranges_ == o.ranges_; }

private:
    std::vector<SampleRange> ranges_;
};

// Parses "A:B" (A < B, decimal); `what` names the option or file in the InputError message.
SampleRange parseSampleRange(const std::string& text, const std::string& what);
// Parses the text form of SampleRanges ("" = empty); throws InputError naming `what`.
SampleRanges parseSampleRanges(const std::string& text, const std::string& what);

}  // namespace bdptref
