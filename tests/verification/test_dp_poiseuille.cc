// Daviet & Bertails-Descoubes 2016, 6.1.1: Bingham Poiseuille flow. The case file shipped in
// cases/ is run through the library; the velocity profile it writes is compared with the analytic
// profile computed here, u(y) = (Re/2)[(1 - y^2) - 2 Bi (1 - |y|)] for |y| >= Bi, u(Bi) inside.
#include "core/max_abs.h"
#include "core/output.h"
#include "models/dp/dp_model.h"
#include "support/csv.h"
#include "support/dp_run.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace
{

  double
  poiseuille(double y, double Bi, double Re)
  {
    const double a = std::max(std::abs(y), Bi);
    return 0.5 * Re * ((1. - a * a) - 2. * Bi * (1. - a));
  }

  double
  poiseuille_shear_rate(double y, double Bi, double Re)
  {
    return std::abs(y) <= Bi ? 0. : Re * (Bi * (y > 0. ? 1. : -1.) - y);
  }

  using granflow::test::read_csv;

  nlohmann::json
  run_case(const std::vector<granflow::Override> &overrides, const std::string &name)
  {
    return granflow::test::run_dp("bingham_poiseuille.prm", overrides, name);
  }
} // namespace

class BinghamPoiseuille : public ::testing::TestWithParam<double>
{};

namespace
{
  /// The run's profile is within 1 % of the analytic one (6.1.1) and parallel, its summary's
  /// max_rel_error is the CSV's, and its plug is rigid: two elements away from the yield surface,
  /// the strain rate the rheology sees vanishes at every constraint point to the solver tolerance
  /// (no regularisation creep). Even the thinnest plug (Bi = 0.1, 48 points) has points there, so
  /// the check is never empty.
  void
  expect_bingham_profile_and_rigid_plug(const nlohmann::json &summary, const double Bi,
                                        const double Re)
  {
    const auto csv = read_csv(summary["dir"].get<std::string>() + "/profiles/velocity.csv");
    ASSERT_EQ(csv.size(), 6u);
    double max_err = 0., max_ref = 0., max_uy = 0.;
    for (std::size_t k = 0; k < csv[0].size(); ++k)
      {
        const double ref = poiseuille(csv[0][k], Bi, Re);
        max_err          = granflow::max_abs(max_err, csv[1][k] - ref);
        max_ref          = granflow::max_abs(max_ref, ref);
        max_uy           = granflow::max_abs(max_uy, csv[2][k]);
      }
    // measured at most 3.7e-4 (Bi = 0.9; 7e-6 at Bi = 0.1)
    EXPECT_LE(max_uy, 1e-3 * max_ref) << "the flow is parallel: u_y = 0";
    ::testing::Test::RecordProperty("max_rel_error_" + std::to_string(Bi),
                                    std::to_string(max_err / max_ref));
    EXPECT_LE(max_err / max_ref, 0.01) << "Bi = " << Bi; // the bound
    // ... and a regression bound, 3 times what was measured (session 31, the fixed point and the
    // interior point alike: 4.8e-5, 1.8e-4, 2.0e-4, 5.9e-4 and 2.8e-3 for Bi = 0.1 to 0.9)
    const double measured = Bi < 0.2   ? 4.8e-5
                            : Bi < 0.4 ? 1.8e-4
                            : Bi < 0.6 ? 2.0e-4
                            : Bi < 0.8 ? 5.9e-4
                                       : 2.8e-3;
    EXPECT_LE(max_err / max_ref, 3. * measured) << "Bi = " << Bi;
    EXPECT_NEAR(summary["max_rel_error"].get<double>(), max_err / max_ref, 1e-8); // CSV precision
    EXPECT_GT(summary["plug"]["points"].get<int>(), 0);
    EXPECT_LE(summary["plug"]["max_scaled_strain_rate_T"].get<double>(),
              summary["plug"]["rigid_threshold"].get<double>());
  }
} // namespace

TEST_P(BinghamPoiseuille, ProfileWithinOnePercentAndRigidPlug)
{
  const double Bi = GetParam();
  const auto   summary =
      run_case({{"Rheology/Bi", std::to_string(Bi)}, {"Output/Write vtu", "false"}},
               "bp" + std::to_string(Bi));
  ASSERT_TRUE(summary["solver"]["converged"].get<bool>());
  expect_bingham_profile_and_rigid_plug(summary, Bi, 1.);
}

// The same channel by the interior point (its split form, which takes mu = 0 where Bi > 0, since
// session 26): measured 0.018 % and 0.28 % at Bi = 0.3 and 0.9 in 29 and 33 iterations, the fixed
// point's errors.
TEST(BinghamPoiseuilleByTheInteriorPoint, ProfileWithinOnePercentAndRigidPlug)
{
  for (const double Bi : {0.3, 0.9})
    {
      const auto summary = run_case({{"Rheology/Bi", std::to_string(Bi)},
                                     {"Solver/Method", "interior point"},
                                     {"Output/Write vtu", "false"}},
                                    "bp_ip" + std::to_string(Bi));
      ASSERT_TRUE(summary["solver"]["converged"].get<bool>()) << Bi;
      EXPECT_EQ(summary["solver"]["method"].get<std::string>(), "interior point");
      expect_bingham_profile_and_rigid_plug(summary, Bi, 1.);
    }
}

INSTANTIATE_TEST_SUITE_P(Daviet611, BinghamPoiseuille, ::testing::Values(0.1, 0.3, 0.5, 0.7, 0.9));

// DP(mu, Bi) with mu > 0 end to end: with an external pressure P on both ends of the channel, the
// continuum's flow is parallel, tau_xx = 0 and p = P everywhere (the discrete P1d point pressures
// oscillate about it; in the plug the stress is not unique), so the yield condition |lambda_T| <=
// mu lambda_N + Bi (the truncated cone of 4.5.2; lambda_N = p in 2D, Property 2) is Bingham's with
// Bi + mu P: the profile is the Bingham profile at that Bingham number. Both solvers, each in the
// cone it handles: the fixed point with mu and Bi, the interior point with mu alone; measured
// 0.12 % and 0.14 % off at h = 0.1 (0.031 % and 0.042 % on the case's mesh). Since session 26 the
// interior point's split form takes Bi > 0 too: DP(0.2, 0.2) in 17 iterations.
TEST(PressureDependentPoiseuille, IsBinghamsWithTheYieldStressAtTheAppliedPressure)
{
  struct Setting
  {
    double      mu, Bi, P;
    const char *method, *residual;
  };
  for (const Setting c : {Setting{0.2, 0.2, 1., "fixed point", "alart-curnier"},
                          Setting{0.3, 0., 1., "interior point", "fischer-burmeister"},
                          Setting{0.2, 0.2, 1., "interior point", "alart-curnier"}})
    {
      const std::string name =
          std::string("pressure_poiseuille_") + c.method + "_Bi" + std::to_string(c.Bi);
      const auto        summary =
          run_case({{"Rheology/mu", std::to_string(c.mu)},
                    {"Rheology/Bi", std::to_string(c.Bi)},
                    {"Boundary conditions/External pressure",
                     "inlet: " + std::to_string(c.P) + ", outlet: " + std::to_string(c.P)},
                    {"Solver/Method", c.method},
                    {"Solver/Residual", c.residual},
                    {"Solver/Inner solver", "apgd"}, // (spg: 167 s on the case's mesh)
                    {"Geometry/Mesh size", "0.1"},
                    {"Output/Reference", "none"},
                    {"Output/Write vtu", "false"}},
                   name);
      ASSERT_TRUE(summary["solver"]["converged"].get<bool>()) << c.method;
      const auto   csv     = read_csv(summary["dir"].get<std::string>() + "/profiles/velocity.csv");
      const double Bi      = c.Bi + c.mu * c.P;
      double       max_err = 0., max_ref = 0.;
      for (std::size_t k = 0; k < csv[0].size(); ++k)
        {
          const double ref = poiseuille(csv[0][k], Bi, 1.);
          max_err          = granflow::max_abs(max_err, csv[1][k] - ref);
          max_ref          = granflow::max_abs(max_ref, ref);
        }
      RecordProperty(name, std::to_string(max_err / max_ref));
      EXPECT_LE(max_err / max_ref, 0.01) << c.method << ": against Bingham at Bi + mu P = " << Bi;
    }
}

class BinghamConvergence : public ::testing::TestWithParam<std::string>
{};

// Daviet 6.1.2 (Fig. 5): under uniform refinement the max-norm and H1 errors against the analytic
// profile decrease at least at order 1.2 (the profile has a kink in u'' at the yield surface, so
// H1 is limited to about 1.5). The domain errors are the model's (summary.json: error_Linf at the
// points of a quadrature rule, error_H1); that they are taken against the right profile is checked
// here on the reference columns of its CSV, and the max-norm error along the profile line is
// computed here from the CSV alone (orders 1.9-2.0 with P1, 1.3-1.5 with P1d).
TEST_P(BinghamConvergence, ErrorsDecreaseUnderRefinement)
{
  const double        Bi = 0.5, Re = 1.;
  std::vector<double> Linf, H1, line_Linf;
  for (int r = 0; r < 3; ++r)
    {
      const auto s = run_case({{"Solver/Stress element", GetParam()},
                               {"Geometry/Mesh size", "0.2"},
                               {"Geometry/Global refinements", std::to_string(r)},
                               {"Output/Write vtu", "false"}},
                              "conv" + GetParam() + std::to_string(r));
      ASSERT_TRUE(s["solver"]["converged"].get<bool>());
      Linf.push_back(s["error_Linf"].get<double>());
      H1.push_back(s["error_H1"].get<double>());
      // y, u_x, u_y, du_x/dy, u_x_reference, du_x/dy_reference
      const auto csv = read_csv(s["dir"].get<std::string>() + "/profiles/velocity.csv");
      ASSERT_EQ(csv.size(), 6u);
      double e = 0.;
      for (std::size_t k = 0; k < csv[0].size(); ++k)
        {
          const double y = csv[0][k];
          ASSERT_NEAR(csv[4][k], poiseuille(y, Bi, Re), 1e-9) << "y = " << y;
          ASSERT_NEAR(csv[5][k], poiseuille_shear_rate(y, Bi, Re), 1e-9) << "y = " << y;
          e = granflow::max_abs(e, csv[1][k] - poiseuille(y, Bi, Re));
        }
      line_Linf.push_back(e);
    }
  // Measured orders (levels 0-1, 1-2): P1 max norm 2.0, 1.84, H1 1.38, 1.53, line 1.93, 1.99;
  // P1d 1.73, 1.38, H1 1.43, 1.35, line 1.31, 1.47. P2-P1's max-norm orders are required at 1.6,
  // so that a loss of its second order shows; the rest at 1.2.
  const double max_norm_order = GetParam() == "P1" ? 1.6 : 1.2;
  for (int r = 0; r + 1 < 3; ++r)
    {
      EXPECT_GE(std::log2(Linf[r] / Linf[r + 1]), max_norm_order) << GetParam() << " level " << r;
      EXPECT_GE(std::log2(H1[r] / H1[r + 1]), 1.2) << GetParam() << " level " << r;
      EXPECT_GE(std::log2(line_Linf[r] / line_Linf[r + 1]), max_norm_order)
          << GetParam() << " level " << r;
    }
}

INSTANTIATE_TEST_SUITE_P(Daviet612, BinghamConvergence, ::testing::Values("P1", "P1d"));
