// Order statistics of a sample (timings, errors, counts): the package's one percentile and median.
#pragma once

#include <vector>

namespace ret3d {

// Linear-interpolated percentile (p in [0, 100], clamped) of the values; 0 for none.
double percentile(std::vector<double> values, double p);

// Median: the middle value, or the mean of the two middle values for an even count; 0 for none.
double median(std::vector<double> values);

// Nearest-rank percentile (p in (0, 100]): the smallest value with at least p % of the values at or below it; 0 for
// none. Unlike percentile() it is always one of the values (a measured timing, not an interpolated one).
double nearestRankPercentile(std::vector<double> values, double p);

}  // namespace ret3d
