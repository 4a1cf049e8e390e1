// Prescribed boundary velocities (Boundary conditions/Velocity, a u_D != 0 in Daviet 2016 (21))
// against analytic solutions computed here:
// - Bingham Couette-Poiseuille flow: the channel of 6.1.1 with its top wall moving;
// - Faxen's drag on a cylinder moving midway between two plane walls (Stokes flow, mu = Bi = 0),
//   an independent reference for the cylinder channel's mesh and for the force on a boundary taken
//   from the reaction of the momentum equation.
#include "support/csv.h"
#include "support/dp_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace
{
  /// Channel y in [-1, 1], u(-1) = 0, u(1) = U, unit body force along x, viscosity 1/Re, yield
  /// stress Bi (mu = 0). The shear stress is tau(y) = tau0 - y, and Re^-1 u' = f(tau) with f(t) =
  /// sign(t) max(|t| - Bi, 0), whose primitive is F(t) = max(|t| - Bi, 0)^2 / 2; so u(y) = Re
  /// (F(tau0 + 1) - F(tau0 - y)), and tau0 is the root of u(1) = U (u(1) increases with tau0).
  /// At U = 0, tau0 = 0 and this is the Bingham Poiseuille profile of 6.1.1.
  struct CouettePoiseuille
  {
    double U, Bi, Re, tau0 = 0.;

    CouettePoiseuille(const double U_, const double Bi_, const double Re_)
        : U(U_)
        , Bi(Bi_)
        , Re(Re_)
    {
      double lo = -10., hi = 10.; // u(1) - U changes sign between them for |U| < 10 Re
      for (int i = 0; i < 200; ++i)
        {
          tau0                         = 0.5 * (lo + hi);
          (velocity(1.) < U ? lo : hi) = tau0;
        }
    }

    double
    F(const double t) const
    {
      const double excess = std::max(std::abs(t) - Bi, 0.);
      return 0.5 * excess * excess;
    }

    double
    velocity(const double y) const
    {
      return Re * (F(tau0 + 1.) - F(tau0 - y));
    }
  };

  /// Faxen's series (H. Faxen 1946): the force per unit length on
  /// a circular cylinder of radius a moving at speed U along, and midway between, two plane walls
  /// a distance l from its axis, in Stokes flow of viscosity eta:
  /// F = 4 pi eta U / (ln(1/k) - 0.9157 + 1.7244 k^2 - 1.7302 k^4 + 2.4056 k^6 - 4.5913 k^8),
  /// k = a / l.
  double
  faxen_drag(const double eta, const double U, const double k)
  {
    const double k2 = k * k;
    return 4. * M_PI * eta * U /
           (std::log(1. / k) - 0.9157 +
            k2 * (1.7244 + k2 * (-1.7302 + k2 * (2.4056 - 4.5913 * k2))));
  }
} // namespace

// The top wall moves at U = 1 and the body force drives the channel along x too. The profile is
// within 1e-3 of its maximum of the analytic one: measured below 1e-6 for the Newtonian channel,
// whose quadratic profile the P2 velocity holds exactly, and 1.4e-5 at Bi = 0.3, whose plug is
// attached to the moving wall (y in [tau0 - Bi, 1], tau0 = sqrt(2) - 0.7). The ends of the
// profile are the walls' velocities. The moving wall's force, from the reaction there, is its
// shear stress: the material drags it along x by 1 - tau0 per unit length.
TEST(MovingWall, BinghamCouettePoiseuilleProfile)
{
  for (const double Bi : {0., 0.3})
    {
      const CouettePoiseuille reference(1., Bi, 1.);
      const std::string       name    = "couette_poiseuille_" + std::to_string(Bi);
      const auto              summary = granflow::test::run_dp("bingham_poiseuille.prm",
                                                               {{"Rheology/Bi", std::to_string(Bi)},
                                                                {"Boundary conditions/No-slip", "bottom"},
                                                                {"Boundary conditions/Velocity", "top: (1, 0)"},
                                                                {"Output/Reference", "none"},
                                                                {"Output/Drag boundary", "top"},
                                                                {"Output/Write vtu", "false"}},
                                                               name);
      ASSERT_TRUE(summary["solver"]["converged"].get<bool>()) << Bi;
      // the material's force on the wall y = 1 (length 1), -sigma n with sigma_xy(1) = tau0 - 1
      // (measured 1e-13 and 9e-6 off)
      EXPECT_NEAR(summary["boundary_force"][0].get<double>(), 1. - reference.tau0, 1e-4) << Bi;
      const auto csv =
          granflow::test::read_csv(summary["dir"].get<std::string>() + "/profiles/velocity.csv");
      double max_err = 0., max_ref = 0.;
      for (std::size_t k = 0; k < csv[0].size(); ++k)
        {
          const double ref = reference.velocity(csv[0][k]);
          max_err          = std::max(max_err, std::abs(csv[1][k] - ref));
          max_ref          = std::max(max_ref, std::abs(ref));
        }
      RecordProperty(name, std::to_string(max_err / max_ref));
      EXPECT_LE(max_err / max_ref, 1e-3) << "Bi = " << Bi << ", tau0 = " << reference.tau0;
      // the profile's ends are 2e-9 inside the walls
      EXPECT_NEAR(csv[1].front(), 0., 1e-8);
      EXPECT_NEAR(csv[1].back(), 1., 1e-8);
    }
}

// In the frame of the cylinder (D = 1/4 in a channel of width 1: k = 1/4), the walls and the
// far field move at -U: Velocity on the walls and on the end the flow enters by, the other end
// open under a pressure high enough that lambda_N > 0 everywhere (so the cone constraint is
// inactive and the flow is Stokes flow of viscosity 1/Re). Gravity across the channel only adds
// hydrostatic pressure (its x-force vanishes: +-U give +-F to 3e-5). The force on the cylinder,
// viscous part included, approaches Faxen's value under refinement: measured +2.6 % at h = 0.1,
// +0.31 % at h = 0.05, +0.05 % at h = 0.025 (and 3e-5 relative closer with the ends 2.5 instead of
// 1.5 widths away).
TEST(MovingWall, CylinderBetweenWallsHasFaxensDrag)
{
  const double U = 1., Re = 1., k = 0.25;
  const double reference = faxen_drag(1. / Re, U, k);
  double       error[2];
  for (const int level : {0, 1})
    {
      const std::string h    = level == 0 ? "0.1" : "0.05";
      const std::string name = "faxen_" + h;
      const auto        s    = granflow::test::run_dp(
                    "cylinder.prm",
                    {{"Rheology/mu", "0"},
                     {"Rheology/Re", "1"},
                     {"Gravity direction", "0, -1"},
                     {"Boundary conditions/No-slip", "cylinder"},
                     {"Boundary conditions/Velocity", "walls: (-1, 0), outlet: (-1, 0)"},
                     {"Boundary conditions/External pressure", "inlet: 400"},
                     {"Solver/Method", "fixed point"},
                     {"Solver/Tolerance", "1e-4"}, // in units of stress, here about 400
                     {"Geometry/Mesh size", h},
                     {"Output/Inflow boundary", "outlet"},
                     {"Output/Write vtu", "false"}},
                    name);
      ASSERT_TRUE(s["solver"]["converged"].get<bool>()) << h;
      ASSERT_GT(s["pressure"]["min"].get<double>(), 0.) << "the cone constraint is active";
      // the material's force on the cylinder, along the walls' motion (-x)
      const double F = -s["boundary_force"][0].get<double>();
      error[level]   = (F - reference) / reference;
      RecordProperty(name, std::to_string(error[level]));
    }
  EXPECT_LE(std::abs(error[1]), 0.005) << "Faxen: " << reference;
  // second order or better in h (measured 8.3 times smaller per halving)
  EXPECT_LE(std::abs(error[1]), std::abs(error[0]) / 4.) << error[0] << ", " << error[1];
}
