#include "bdptref/film.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

FilmErrorSummary summarizeError(const Film& film) {
    FilmErrorSummary e;
    std::vector<double> r;
    double sumV = 0, sumM = 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            if (film.count(x, y) == 0) continue;
            const DVec3 m = film.mean(x, y), v = film.varianceOfMean(x, y);
            const double mm = (m.x + m.y + m.z) / 3.0, vv = (v.x + v.y + v.z) / 3.0;
            sumV += v.x + v.y + v.z;
            sumM += m.x + m.y + m.z;
            if (mm > 0) r.push_back(std::sqrt(vv) / mm);
        }
    e.pixels = r.size();
    if (!r.empty()) {
        auto quantile = [&](double q) {
            const size_t k = std::min(r.size() - 1, size_t(q * double(r.size())));
            std::nth_element(r.begin(), r.begin() + std::ptrdiff_t(k), r.end());
            return r[k];
        };
        e.medianRelativeStandardError = quantile(0.5);
        e.p95RelativeStandardError = quantile(0.95);
    }
    e.imageRelativeStandardError = sumM > 0 ? std::sqrt(sumV) / sumM : 0.0;
    return e;
}

}  // namespace bdptref
