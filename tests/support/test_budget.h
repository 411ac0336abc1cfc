// Sample budgets of the expensive statistical tests. Under AddressSanitizer the renderer runs
// ~10x slower, and the whole suite must still fit the CI budget; the statistical tests therefore
// take fewer samples there. This is legitimate because every tolerance is k * sigma with sigma
// estimated in the same run: fewer samples widen the tolerance honestly, they do not invalidate
// it. Power checks ("this comparison must FAIL on a 5% error") need their full sample count and
// keep it (use fullSamples() for them).
#pragma once

namespace bdptref::test {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitizedBuild = true;
#else
constexpr bool kSanitizedBuild = false;
#endif
#else
constexpr bool kSanitizedBuild = false;
#endif

// Divides sample counts in sanitizer builds (4: measured to bring the suite's slowest statistical
// tests from minutes to well under one minute each under ASan+UBSan).
constexpr int kSanitizerSampleDivisor = kSanitizedBuild ? 4 : 1;

// An effect that N samples detect is detected by N / d samples when it is sqrt(d) times larger:
// power checks of tests that use scaledSamples() scale their effect by this.
constexpr double kSanitizerEffectScale = kSanitizedBuild ? 2.0 : 1.0;  // sqrt(kSanitizerSampleDivisor)

// `spp` for tests whose tolerance is estimated from the same run; never below `minimum`.
inline int scaledSamples(int spp, int minimum = 16) {
    const int s = spp / kSanitizerSampleDivisor;
    return s < minimum ? (spp < minimum ? spp : minimum) : s;
}
// For power checks: the full count in every build.
inline int fullSamples(int spp) { return spp; }

}  // namespace bdptref::test
