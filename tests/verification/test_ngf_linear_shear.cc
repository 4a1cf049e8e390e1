// Henann & Kamrin 2016, 6.1 (Fig. 1): linear shear flow with gravity. The shipped case file is run
// through the library at the paper's wall speeds and wall pressures; its steady velocity profile,
// mu_wall (from the wall reactions) and shear-band width W are compared with the finite-difference
// solution of the 1D reduction (90) computed here on a 0.01 d grid at the same wall speed:
// v / v_wall within 0.03 at every node, mu_wall within 1 %, W / d within 5 % (issue #3 a).
#include "models/ngf/ngf_model.h"
#include "postprocess/nonlocal_1d.h"
#include "support/ngf_run.h"
#include "support/reference_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace
{
  using namespace granflow;

  const std::string case_file =
      std::string(GRANFLOW_SOURCE_DIR) + "/cases/henann2016/linear_shear_gravity.prm";

  struct Point
  {
    double P_wall; // P_wall / (phi rho_s G d)
    double v_wall; // v_wall / sqrt(G d)
  };

  class LinearShear : public ::testing::TestWithParam<Point>
  {
  };

  TEST_P(LinearShear, MatchesTheFiniteDifferenceSolutionOf90)
  {
    const Point        c = GetParam();
    std::ostringstream name;
    name << "ngf_linear_shear_" << c.P_wall << "_" << c.v_wall;
    const auto parameters =
        ngf::load_parameters(case_file, {{"Loading/Wall pressure", std::to_string(c.P_wall)},
                                         {"Loading/Wall speed", std::to_string(c.v_wall)},
                                         {"Output/Reference", "none"},
                                         {"Output/Write vtu", "false"}});
    const auto        summary = test::run_ngf(parameters, name.str());
    const std::string dir     = summary["output_directory"];

    // The reference, from the case's own physical parameters.
    const auto                       &m = parameters.material;
    const double                      d = m.nonlocal.d;
    postprocess::LinearShearGravity1d fd;
    fd.material = m.nonlocal;
    fd.phi      = m.phi;
    fd.G        = m.G;
    fd.P_wall   = c.P_wall * m.phi * m.nonlocal.rho_s * m.G * d;
    fd.depth    = parameters.geometry.depth * d;
    fd.h        = 0.01 * d;
    const auto reference =
        postprocess::solve_linear_shear_gravity_for_speed(fd, c.v_wall * std::sqrt(m.G * d));

    test::expect_matches_reference(summary, dir, reference, d);
  }

  // Fig. 1b: the wall speed at P_wall = 6.67; Fig. 1d: the wall pressure at v_wall = 1e-3.
  INSTANTIATE_TEST_SUITE_P(Speeds, LinearShear,
                           ::testing::Values(Point{6.67, 1e-4}, Point{6.67, 1e-2}, Point{6.67, 1.}),
                           [](const ::testing::TestParamInfo<Point> &info) {
                             return test::test_name("P" + std::to_string(info.param.P_wall) + "_v" +
                                                    std::to_string(info.param.v_wall));
                           });
  INSTANTIATE_TEST_SUITE_P(Pressures, LinearShear,
                           ::testing::Values(Point{3.33, 1e-3}, Point{6.67, 1e-3},
                                             Point{12.5, 1e-3}, Point{25., 1e-3}, Point{50., 1e-3},
                                             Point{100., 1e-3}),
                           [](const ::testing::TestParamInfo<Point> &info) {
                             return test::test_name("P" + std::to_string(info.param.P_wall) + "_v" +
                                                    std::to_string(info.param.v_wall));
                           });
} // namespace
