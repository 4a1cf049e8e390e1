// Test support: comparing a profile granflow wrote with a finite-difference reference profile.
#pragma once

#include "core/max_abs.h"
#include "postprocess/nonlocal_1d.h"
#include "support/csv.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

namespace granflow::test
{
  /// max_i |v_i - v_ref(x_i) / v_ref_wall|, with x_i the distance from the driven wall in units of
  /// d and v_ref interpolated linearly on the reference's uniform grid (which starts at the wall).
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
        worst          = max_abs(worst, v[i] - r);
      }
    return worst;
  }
  /// The same for a computed 1D profile (nodes from its wall, v / v_wall) against the reference.
  inline double
  max_difference_to_reference(const postprocess::Nonlocal1dProfile &profile,
                              const postprocess::Nonlocal1dProfile &reference, const double d)
  {
    std::vector<double> x_over_d, v;
    for (std::size_t a = 0; a < profile.x.size(); ++a)
      {
        x_over_d.push_back((profile.x[a] - profile.x.front()) / d);
        v.push_back(profile.v[a] / profile.v_wall);
      }
    return max_difference_to_reference(x_over_d, v, reference, d);
  }

  /// Issue #3 a, b: a run's profiles/velocity.csv within 0.03 of the wall speed of the reference at
  /// every node, mu_wall within 1 %, W / d within 5 %, and at most 6 Newton iterations per
  /// increment.
  inline void
  expect_matches_reference(const nlohmann::json &summary, const std::string &dir,
                           const postprocess::Nonlocal1dProfile &reference, const double d)
  {
    const auto profile = read_csv(dir + "/profiles/velocity.csv");
    ASSERT_GE(profile.size(), 2U);
    const double worst   = max_difference_to_reference(profile[0], profile[1], reference, d);
    const double mu_wall = summary["mu_wall"];
    const double W       = summary["shear_band_width_over_d"];
    ::testing::Test::RecordProperty("max_velocity_difference", std::to_string(worst));
    ::testing::Test::RecordProperty("mu_wall", std::to_string(mu_wall) + " (FD " +
                                                   std::to_string(reference.mu_wall) + ")");
    ::testing::Test::RecordProperty("W_over_d", std::to_string(W) + " (FD " +
                                                    std::to_string(reference.shear_band_width / d) +
                                                    ")");
    EXPECT_LE(worst, 0.03);
    EXPECT_NEAR(mu_wall, reference.mu_wall, 0.01 * reference.mu_wall);
    EXPECT_NEAR(W, reference.shear_band_width / d, 0.05 * reference.shear_band_width / d);
    EXPECT_LE(summary["newton"]["iterations_per_increment"].get<double>(), 6.);
  }

  /// A test-name suffix from a text: every character that is not alphanumeric becomes '_'.
  inline std::string
  test_name(std::string name)
  {
    for (char &c : name)
      if (!std::isalnum(static_cast<unsigned char>(c)))
        c = '_';
    return name;
  }
} // namespace granflow::test
