// Daviet & Bertails-Descoubes 2016, 6.1.3 (Fig. 7): Bagnold profile of a layer on a plane inclined
// at alpha = atan(1.1 mu), mu = 0.5, eta = |D(u)|. The shipped case is run and its profile compared
// with the analytic solution computed here, from the shear balance of (23),
// (2 / Re) eta D_xy = (sin a - mu cos a)(1 - y) with eta = |D| = u' / 2:
//   u'(y) = sqrt(2 Re (sin a - mu cos a)) sqrt(1 - y),  u(y) = (2/3) u'(0) (1 - (1 - y)^{3/2}).
// The paper's case is Re = 1; Re = 2 checks that the viscous term carries 1 / Re (the reference
// written for Re = 1 only was 41 % off there, unnoticed).
#include "core/max_abs.h"
#include "core/output.h"
#include "models/dp/dp_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

class Bagnold : public ::testing::TestWithParam<double>
{
};

TEST_P(Bagnold, VelocityAndShearRateMatchTheAnalyticProfile)
{
  const double      Re         = GetParam();
  const std::string case_file = std::string(GRANFLOW_SOURCE_DIR) + "/cases/daviet2016/bagnold.prm";
  const auto        parameters = granflow::dp::load_parameters(
             case_file, {{"Output/Write vtu", "false"}, {"Rheology/Re", std::to_string(Re)}});
  const std::string dir = ::testing::TempDir() + "/granflow_bagnold_Re" + std::to_string(Re);
  std::filesystem::remove_all(dir);
  nlohmann::json summary;
  {
    granflow::OutputDirectory out(dir);
    granflow::Logger          log(out.file("log.txt"), false);
    summary = granflow::dp::run(parameters, out, log).summary;
    out.commit();
  }
  ASSERT_TRUE(summary["solver"]["converged"].get<bool>());

  const double mu = 0.5, alpha = std::atan(1.1 * mu);
  const double  c = std::sqrt(2. * Re * (std::sin(alpha) - mu * std::cos(alpha)));
  std::ifstream in(dir + "/profiles/velocity.csv");
  std::string   line;
  std::getline(in, line);
  double max_u = 0., max_du = 0., err_u = 0., err_du = 0.;
  int    rows  = 0;
  while (std::getline(in, line))
    {
      std::stringstream   s(line);
      std::string         cell;
      std::vector<double> v;
      while (std::getline(s, cell, ','))
        v.push_back(std::stod(cell));
      const double y = v[0], u = v[1], du = v[3];
      const double u_ref  = 2. / 3. * c * (1. - std::pow(1. - y, 1.5));
      const double du_ref = c * std::sqrt(1. - y);
      max_u               = std::max(max_u, u_ref);
      max_du              = std::max(max_du, du_ref);
      err_u               = granflow::max_abs(err_u, u - u_ref);
      // The analytic shear rate has an infinite slope at the free surface (sqrt(1 - y)), which
      // no polynomial gradient resolves; the top 5 % of the layer is left out of this check.
      if (y <= 0.95)
        err_du = granflow::max_abs(err_du, du - du_ref);
      ++rows;
    }
  ASSERT_GT(rows, 50);
  // The issue asks for 2 %. Measured (session 31): velocity 1.13e-4 and shear rate 1.05e-3 at
  // Re = 1 (1.07e-4, 1.06e-3 at Re = 2); bounds of 5e-4 and 5e-3 show a regression far inside
  // the issue's.
  EXPECT_LE(err_u / max_u, 5e-4);
  EXPECT_LE(err_du / max_du, 5e-3);
  // The summary's own comparison uses the same analytic solution.
  EXPECT_NEAR(summary["max_rel_error"].get<double>(), err_u / max_u, 1e-6);
  RecordProperty("velocity_rel_error", std::to_string(err_u / max_u));
  RecordProperty("shear_rate_rel_error", std::to_string(err_du / max_du));
}

INSTANTIATE_TEST_SUITE_P(Re, Bagnold, ::testing::Values(1., 2.));
