// Test support: comparing a profile granflow wrote with a finite-difference reference profile.
#pragma once

#include "postprocess/nonlocal_1d.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace granflow::test
{
  /// max_i |v_i - v_ref(x_i) / v_ref_wall|, with x_i the distance from the driven wall in units of d
  /// and v_ref interpolated linearly on the reference's uniform grid (which starts at the wall).
  inline double
  max_difference_to_reference(const std::vector<double> &x_over_d, const std::vector<double> &v,
                              const postprocess::Nonlocal1dProfile &reference, const double d)
  {
    double worst = 0.;
    for (std::size_t i = 0; i < x_over_d.size(); ++i)
      {
        const double s = x_over_d[i] * d / (reference.x[1] - reference.x[0]);
        const auto   k = std::min<std::size_t>(static_cast<std::size_t>(s), reference.x.size() - 2);
        const double t = s - k;
        const double r = ((1. - t) * reference.v[k] + t * reference.v[k + 1]) / reference.v_wall;
        worst          = std::max(worst, std::abs(v[i] - r));
      }
    return worst;
  }
} // namespace granflow::test
