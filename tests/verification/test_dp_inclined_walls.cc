// Velocity conditions on boundaries at any inclination: Zero normal velocity (free slip) and Zero
// tangential velocity (flow normal to the boundary). Bingham Poiseuille flow (Daviet 6.1.1) in a
// channel turned by 30 degrees, with the body force along it, is the axis-aligned flow turned by
// 30 degrees: the analytic profile u(y') = (Re/2)[(1 - y'^2) - 2 Bi (1 - |y'|)] (plug |y'| <= Bi)
// along the channel, in the channel's own coordinate y'.
#include "core/max_abs.h"
#include "support/csv.h"
#include "support/dp_run.h"
#include "support/structured_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace
{
  using granflow::test::read_csv;
  using granflow::test::run_dp;

  constexpr double pi = 3.14159265358979323846;

  double
  poiseuille(double y, double Bi, double Re)
  {
    const double a = std::max(std::abs(y), Bi);
    return 0.5 * Re * ((1. - a * a) - 2. * Bi * (1. - a));
  }

  std::string
  str(double x)
  {
    std::ostringstream s;
    s << x;
    return s.str();
  }

  std::string
  point(double x, double y)
  {
    std::ostringstream s;
    s.precision(17);
    s << x << ", " << y;
    return s.str();
  }

  /// Velocity along and across the channel at the profile's samples, and their y'.
  struct ChannelProfile
  {
    std::vector<double> y, along, across;
  };

  /// The profile of a run whose line is x' = x_line, y' from y0 to y1 (channel coordinates,
  /// turned by `angle`).
  ChannelProfile
  channel_profile(const nlohmann::json &summary, double angle, double x_line)
  {
    const auto     csv = read_csv(summary["dir"].get<std::string>() + "/profiles/velocity.csv");
    const double   c = std::cos(angle), s = std::sin(angle);
    ChannelProfile p;
    for (std::size_t k = 0; k < csv[0].size(); ++k)
      {
        // The first column is y (it varies more along the line for |angle| < 45 degrees):
        // y = x' sin + y' cos.
        p.y.push_back((csv[0][k] - x_line * s) / c);
        p.along.push_back(csv[1][k] * c + csv[2][k] * s);
        p.across.push_back(-csv[1][k] * s + csv[2][k] * c);
      }
    return p;
  }
} // namespace

TEST(InclinedWalls, TurnedChannelGivesTheTurnedFlow)
{
  // The same structured mesh of [-0.5, 0.5] x [-1, 1], axis-aligned with Zero y-velocity at its
  // ends, and turned by 30 degrees with Zero tangential velocity there (the ends' tangent is
  // the turned y axis). The two discrete problems are the same up to the rotation, so the
  // velocities agree to the solver's accuracy; both match the analytic profile.
  const double   Bi = 0.33, angle = pi / 6., x_line = -0.25; // yield surface inside elements
  ChannelProfile profile[2];
  for (const int turned : {0, 1})
    {
      const double a    = turned ? angle : 0.;
      const auto   mesh = ::testing::TempDir() + "/channel_" + std::to_string(turned) + ".msh";
      granflow::test::write_rectangle_msh(mesh, 10, 40, -0.5, 0.5, -1., 1., a);
      const double c = std::cos(a), s = std::sin(a);
      const auto   summary =
          run_dp("bingham_poiseuille.prm",
                 {{"Geometry/Shape", "file"},
                  {"Geometry/Mesh file", mesh},
                  {"Gravity direction", point(c, s)},
                  {"Rheology/Bi", std::to_string(Bi)},
                  {"Boundary conditions/Zero y-velocity", turned ? "" : "inlet, outlet"},
                  {"Boundary conditions/Zero tangential velocity", turned ? "inlet, outlet" : ""},
                  {"Output/Reference", "none"},
                  {"Output/Profile start", point(c * x_line + s, s * x_line - c)},
                  {"Output/Profile end", point(c * x_line - s, s * x_line + c)},
                  {"Output/Write vtu", "false"}},
                 "turned_channel_" + std::to_string(turned));
      ASSERT_TRUE(summary["solver"]["converged"].get<bool>());
      profile[turned] = channel_profile(summary, a, x_line);
      // The discharge is int u dy' over the width (Simpson's rule on the analytic profile).
      double Q = 0.;
      for (int k = 0; k <= 2000; ++k)
        Q += (k == 0 || k == 2000 ? 1.
              : k % 2             ? 4.
                                  : 2.) *
             poiseuille(-1. + k / 1000., Bi, 1.) / 3000.;
      const auto &outflow = summary["volume_outflow"];
      EXPECT_NEAR(outflow["outlet"].get<double>(), Q, 0.01 * Q);
      EXPECT_NEAR(outflow["inlet"].get<double>(), -Q, 0.01 * Q);
    }
  ASSERT_EQ(profile[0].y.size(), 201u);
  ASSERT_EQ(profile[1].y.size(), profile[0].y.size());
  double max_ref = 0., max_error = 0., max_difference = 0., max_across = 0.;
  for (std::size_t k = 0; k < profile[0].y.size(); ++k)
    {
      ASSERT_NEAR(profile[1].y[k], profile[0].y[k], 1e-9);
      const double ref = poiseuille(profile[0].y[k], Bi, 1.);
      max_ref          = std::max(max_ref, ref);
      max_error        = granflow::max_abs(max_error, profile[1].along[k] - ref);
      max_difference   = granflow::max_abs(
            granflow::max_abs(max_difference, profile[1].along[k] - profile[0].along[k]),
            profile[1].across[k] - profile[0].across[k]);
      max_across = granflow::max_abs(max_across, profile[1].across[k]);
    }
  RecordProperty("max_rel_error", str(max_error / max_ref));
  RecordProperty("turned_minus_aligned", str(max_difference / max_ref));
  EXPECT_LE(max_error, 0.01 * max_ref);
  EXPECT_LE(max_across, 1e-4 * max_ref) << "the flow runs along the turned channel";
  EXPECT_LE(max_difference, 1e-4 * max_ref) << "the turned problem is the aligned one, turned";
}

TEST(InclinedWalls, FreeSlipCentrelineGivesHalfThePoiseuilleFlowAndCarriesNoShear)
{
  // Half of the turned channel, y' in [0, 1], with a free-slip wall (Zero normal velocity) on
  // the centreline y' = 0, where the full channel's shear stress vanishes by symmetry: the flow
  // is the full channel's, and the no-slip wall y' = 1 carries the whole body force on the
  // half (area 1, along the channel). The ends are Zero tangential velocity; at their corners
  // with the centreline both conditions fix the same direction, so the velocity there is free
  // along the channel.
  const double Bi = 0.37, angle = pi / 6., x_line = -0.25, c = std::cos(angle), s = std::sin(angle);
  const auto   mesh = ::testing::TempDir() + "/half_channel.msh";
  granflow::test::write_rectangle_msh(mesh, 10, 20, -0.5, 0.5, 0., 1., angle);
  double along_force[2];
  for (const std::string wall : {"top", "bottom"})
    {
      const auto summary =
          run_dp("bingham_poiseuille.prm",
                 {{"Geometry/Shape", "file"},
                  {"Geometry/Mesh file", mesh},
                  {"Gravity direction", point(c, s)},
                  {"Rheology/Bi", std::to_string(Bi)},
                  {"Boundary conditions/No-slip", "top"},
                  {"Boundary conditions/Zero normal velocity", "bottom"},
                  {"Boundary conditions/Zero y-velocity", ""},
                  {"Boundary conditions/Zero tangential velocity", "inlet, outlet"},
                  {"Output/Reference", "none"},
                  {"Output/Drag boundary", wall},
                  {"Output/Profile start", point(c * x_line, s * x_line)},
                  {"Output/Profile end", point(c * x_line - s, s * x_line + c)},
                  {"Output/Write vtu", "false"}},
                 "half_channel_" + wall);
      ASSERT_TRUE(summary["solver"]["converged"].get<bool>());
      const auto force              = summary["boundary_force"];
      along_force[wall == "bottom"] = force[0].get<double>() * c + force[1].get<double>() * s;
      if (wall != "top")
        continue;
      const ChannelProfile p = channel_profile(summary, angle, x_line);
      ASSERT_GE(p.y.size(), 100u);
      double max_ref = 0., max_error = 0., max_across = 0.;
      for (std::size_t k = 0; k < p.y.size(); ++k)
        {
          const double ref = poiseuille(p.y[k], Bi, 1.);
          max_ref          = std::max(max_ref, ref);
          max_error        = granflow::max_abs(max_error, p.along[k] - ref);
          max_across       = granflow::max_abs(max_across, p.across[k]);
        }
      RecordProperty("max_rel_error", str(max_error / max_ref));
      EXPECT_LE(max_error, 0.01 * max_ref);
      EXPECT_LE(max_across, 1e-4 * max_ref);
      // The velocity on the slip wall is along it, and as large as the plug's.
      EXPECT_NEAR(p.along.front(), poiseuille(0., Bi, 1.), 0.01 * max_ref);
    }
  EXPECT_NEAR(along_force[0], 1., 2e-3) << "the no-slip wall carries the body force";
  // A free-slip wall's reaction is normal to it, so the force along it is zero but for rounding
  // (measured: 8e-22); a tangential reaction at its corners with the ends, or a viscous traction
  // taken off it wrongly, would show here.
  RecordProperty("free_slip_along_force", str(along_force[1]));
  EXPECT_NEAR(along_force[1], 0., 1e-10) << "the free-slip centreline carries no shear";
}

TEST(InclinedWalls, FlowFollowsAKinkedFreeSlipWallAndDoesNotLeakThroughIt)
{
  // A channel with a bump: its walls rise with slope 0.3 from x = -0.25 to 0 and fall back by
  // x = 0.25 (kinks of 16.7 degrees at x = -0.25 and 0.25, of 33.4 degrees at x = 0), free slip
  // on the bottom (two boundaries: b1 for x < 0, b2 for x > 0), no slip on the top. At a kink
  // node the direction is the consistent normal: the flux through b1 or b2 alone is not zero,
  // because of the kink where they meet, but their sum is, and the flow passes each kink.
  const auto mesh = ::testing::TempDir() + "/bump_channel.msh";
  granflow::test::write_rectangle_msh(
      mesh, 20, 20, -0.5, 0.5, -1., 1., 0., [](int i) { return i < 10 ? "b1" : "b2"; },
      [](double x) { return 0.3 * std::max(0., 0.25 - std::abs(x)); });
  const auto summary = run_dp("bingham_poiseuille.prm",
                              {{"Geometry/Shape", "file"},
                               {"Geometry/Mesh file", mesh},
                               {"Rheology/Bi", "0.2"},
                               {"Boundary conditions/No-slip", "top"},
                               {"Boundary conditions/Zero normal velocity", "b1, b2"},
                               {"Boundary conditions/Zero y-velocity", ""},
                               {"Boundary conditions/Zero tangential velocity", "inlet, outlet"},
                               {"Output/Reference", "none"},
                               {"Output/Profile start", "-0.25, -1"},
                               {"Output/Profile end", "-0.25, 1"},
                               {"Output/Write vtu", "false"}},
                              "bump_channel");
  ASSERT_TRUE(summary["solver"]["converged"].get<bool>());
  const auto  &outflow = summary["volume_outflow"];
  const double Q       = outflow["outlet"].get<double>();
  ASSERT_GT(Q, 0.1);
  EXPECT_GT(std::abs(outflow["b1"].get<double>()), 1e-4 * Q) << "each face leaks at the kink";
  EXPECT_NEAR(outflow["b1"].get<double>() + outflow["b2"].get<double>(), 0., 1e-12 * Q);
  EXPECT_NEAR(summary["volume_outflow_total"].get<double>(), summary["dilation_rate"].get<double>(),
              1e-10 * Q);
  // The kink node (-0.25, -1) joins a face of length h (normal (0, -1)) and one of length
  // h sqrt(1.09) (normal (0.3, -1) / sqrt(1.09)); weighted by their lengths, the normal is along
  // (0.3, -2), and the velocity there along (2, 0.3). The profile's first sample is 2e-9 above it.
  const auto profile = read_csv(summary["dir"].get<std::string>() + "/profiles/velocity.csv");
  ASSERT_NEAR(profile[0].front(), -1., 1e-8);
  const double u_x = profile[1].front(), u_y = profile[2].front();
  EXPECT_GT(u_x, 0.3 * Q);
  EXPECT_NEAR(u_y, 0.15 * u_x, 1e-6 * u_x);
}

TEST(InclinedWalls, CornersOfAnyKindAreFixed)
{
  // Two corners that are not kinks, where a node must not move. (1) A closed V of free-slip
  // walls 15 degrees either side of the vertical: their normals differ by 150 degrees, their
  // lines by 30; the apex, averaged along the lines, moved at -0.0126 and the V leaked. (2) A
  // channel whose slip floor meets ends slanted by 16.7 degrees, each end normal to the flow
  // (Zero tangential velocity): the two conditions fix directions 17 degrees apart, which were
  // averaged, and the floor let 0.26 % of the discharge through.
  const auto wedge = ::testing::TempDir() + "/closed_v.msh";
  granflow::test::write_wedge_msh(wedge, 20, std::tan(pi / 12.));
  const auto v = run_dp("bingham_poiseuille.prm",
                        {{"Geometry/Shape", "file"},
                         {"Geometry/Mesh file", wedge},
                         {"Gravity direction", "0, -1"},
                         {"Rheology/Bi", "0.01"},
                         {"Boundary conditions/No-slip", ""},
                         {"Boundary conditions/Zero y-velocity", ""},
                         {"Boundary conditions/Zero normal velocity", "left, right"},
                         {"Output/Reference", "none"},
                         {"Output/Profile start", "0, 0"},
                         {"Output/Profile end", "0, 1"},
                         {"Output/Write vtu", "false"}},
                        "closed_v");
  ASSERT_TRUE(v["solver"]["converged"].get<bool>());
  for (const char *wall : {"left", "right"})
    EXPECT_LE(std::abs(v["volume_outflow"][wall].get<double>()), 1e-12) << wall;
  const auto apex = read_csv(v["dir"].get<std::string>() + "/profiles/velocity.csv");
  EXPECT_LE(std::hypot(apex[1].front(), apex[2].front()), 1e-6) << "the apex is fixed";

  const auto channel = ::testing::TempDir() + "/slanted_ends.msh";
  granflow::test::write_rectangle_msh(channel, 10, 20, -0.5, 0.5, -1., 1., 0., {}, {},
                                      [](double y) { return 0.3 * (y + 1.); });
  const auto c = run_dp("bingham_poiseuille.prm",
                        {{"Geometry/Shape", "file"},
                         {"Geometry/Mesh file", channel},
                         {"Rheology/Bi", "0.2"},
                         {"Boundary conditions/No-slip", "top"},
                         {"Boundary conditions/Zero y-velocity", ""},
                         {"Boundary conditions/Zero normal velocity", "bottom"},
                         {"Boundary conditions/Zero tangential velocity", "inlet, outlet"},
                         {"Output/Reference", "none"},
                         {"Output/Profile start", "0, -1"},
                         {"Output/Profile end", "0.5, 1"},
                         {"Output/Write vtu", "false"}},
                        "slanted_ends");
  ASSERT_TRUE(c["solver"]["converged"].get<bool>());
  const double Q = c["volume_outflow"]["outlet"].get<double>();
  ASSERT_GT(std::abs(Q), 1e-3);
  EXPECT_LE(std::abs(c["volume_outflow"]["bottom"].get<double>()), 1e-12 * std::abs(Q));
}

TEST(InclinedWalls, BoundaryForcesBalanceTheWeightWithAPressureOnAPartlyFixedEnd)
{
  // The channel (area 2, unit body force along x) with ends normal to the flow and a pressure
  // of 0.3 on its outlet: the forces of the material on the four boundaries add up to its weight,
  // (2, 0). The outlet's share is the pressure it carries along the direction it leaves free
  // (boundary_force had only the reaction, 0, there, and the four added up to 1.4).
  const auto mesh = ::testing::TempDir() + "/pressed_channel.msh";
  granflow::test::write_rectangle_msh(mesh, 10, 20, -0.5, 0.5, -1., 1.);
  double total[2] = {0., 0.};
  for (const char *boundary : {"bottom", "top", "inlet", "outlet"})
    {
      const auto s = run_dp("bingham_poiseuille.prm",
                            {{"Geometry/Shape", "file"},
                             {"Geometry/Mesh file", mesh},
                             {"Rheology/Bi", "0.2"},
                             {"Boundary conditions/Zero y-velocity", ""},
                             {"Boundary conditions/Zero tangential velocity", "inlet, outlet"},
                             {"Boundary conditions/External pressure", "outlet: 0.3"},
                             {"Output/Reference", "none"},
                             {"Output/Drag boundary", boundary},
                             {"Output/Write vtu", "false"}},
                            std::string("pressed_channel_") + boundary);
      ASSERT_TRUE(s["solver"]["converged"].get<bool>()) << boundary;
      total[0] += s["boundary_force"][0].get<double>();
      total[1] += s["boundary_force"][1].get<double>();
      if (std::string(boundary) == "outlet")
        {
          EXPECT_NEAR(s["boundary_force"][0].get<double>(), 0.6, 1e-6);
        }
    }
  EXPECT_NEAR(total[0], 2., 1e-4);
  EXPECT_NEAR(total[1], 0., 1e-4);
}
