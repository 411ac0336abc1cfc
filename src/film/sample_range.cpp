#include "bdptref/sample_range.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace bdptref {

bool SampleRanges::add(SampleRange r) {
    if (r.begin >= r.end) return true;  // an empty range adds nothing
    for (const SampleRange& h : ranges_)
        if (r.begin < h.end && h.begin < r.end) return false;
    ranges_.push_back(r);
    std::sort(ranges_.begin(), ranges_.end(), [](const SampleRange& a, const SampleRange& b) { return a.begin < b.begin; });
    std::vector<SampleRange> joined;
    for (const SampleRange& h : ranges_) {
        if (!joined.empty() && joined.back().end == h.begin) joined.back().end = h.end;
        else joined.push_back(h);
    }
    ranges_ = std::move(joined);
    return true;
}

uint64_t SampleRanges::total() const {
    uint64_t n = 0;
    for (const SampleRange& r : ranges_) n += r.size();
    return n;
}

std::string SampleRanges::text() const {
    std::string s;
    for (const SampleRange& r : ranges_) {
        if (!s.empty()) s += ',';
        s += std::to_string(r.begin) + ":" + std::to_string(r.end);
    }
    return s;
}

namespace {

bool parseIndex(const std::string& s, uint64_t* v) {
    if (s.empty() || s.size() > 20) return false;
    for (char c : s)
        if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    try {
        *v = std::stoull(s);
    } catch (const std::out_of_range&) {  // above 2^64 - 1
        return false;
    }
    return true;
}

}  // namespace

SampleRange parseSampleRange(const std::string& text, const std::string& what) {
    const size_t colon = text.find(':');
    SampleRange r;
    if (colon == std::string::npos || !parseIndex(text.substr(0, colon), &r.begin) ||
        !parseIndex(text.substr(colon + 1), &r.end) || r.begin >= r.end)
        throw InputError(what + ": expected a sample range A:B with integers 0 <= A < B, got '" + text + "'");
    return r;
}

SampleRanges parseSampleRanges(const std::string& text, const std::string& what) {
    SampleRanges rs;
    size_t start = 0;
    while (start < text.size()) {
        size_t comma = text.find(',', start);
        if (comma == std::string::npos) comma = text.size();
        if (!rs.add(parseSampleRange(text.substr(start, comma - start), what)))
            throw InputError(what + ": overlapping sample ranges in '" + text + "'");
        start = comma + 1;
    }
    return rs;
}

}  // namespace bdptref
