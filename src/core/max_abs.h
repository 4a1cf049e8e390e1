// A running maximum of |x| that keeps a NaN. std::max(m, NaN) returns m, so an error, a change
// or a residual that is NaN at one point would be dropped, and its comparison with a bound would
// pass.
#pragma once

#include <cmath>

namespace granflow
{
  /// max(m, |x|), or NaN if either is NaN.
  inline double
  max_abs(const double m, const double x)
  {
    const double a = std::abs(x);
    return (a > m || std::isnan(a)) ? a : m;
  }
} // namespace granflow
