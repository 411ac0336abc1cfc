#include "bdptref/rng.h"

namespace bdptref {

namespace {
// Constants of Random123's philox4x32 (Salmon et al. 2011, table 2).
constexpr uint32_t kM0 = 0xD2511F53u, kM1 = 0xCD9E8D57u;
constexpr uint32_t kW0 = 0x9E3779B9u, kW1 = 0xBB67AE85u;

inline void mulhilo(uint32_t a, uint32_t b, uint32_t* hi, uint32_t* lo) {
    const uint64_t p = uint64_t(a) * uint64_t(b);
    *hi = uint32_t(p >> 32);
    *lo = uint32_t(p);
}
}  // namespace

PhiloxCounter philox4x32_10(PhiloxCounter c, PhiloxKey k) {
    for (int round = 0; round < 10; ++round) {
        if (round > 0) {  // the key is bumped between rounds, not before the first
            k[0] += kW0;
            k[1] += kW1;
        }
        uint32_t hi0, lo0, hi1, lo1;
        mulhilo(kM0, c[0], &hi0, &lo0);
        mulhilo(kM1, c[2], &hi1, &lo1);
        c = {hi1 ^ c[1] ^ k[0], lo1, hi0 ^ c[3] ^ k[1], lo0};
    }
    return c;
}

}  // namespace bdptref
