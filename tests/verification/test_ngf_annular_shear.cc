// Henann & Kamrin 2016, 6.2 (Fig. 3): annular shear flow without gravity on one row of
// generalized-axisymmetric quads. The shipped case file is run through the library at the paper's
// rotation rates and inner radii; its steady velocity profile, mu_wall (from the moment of the
// inner wall) and shear-band width are compared with the finite-difference solution of the 1D
// reduction (92) with the exact Couette kinematics (shear rate -r d(v/r)/dr), computed here on a
// 0.01 d grid at the same wall speed: v / v_wall within 0.03 at every node, mu_wall within 1 %, W /
// d within 5 % (issue #3 b).
#include "core/max_abs.h"
#include "models/ngf/ngf_model.h"
#include "postprocess/nonlocal_1d.h"
#include "support/ngf_run.h"
#include "support/reference_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

namespace
{
  using namespace granflow;

  const std::string case_file =
      std::string(GRANFLOW_SOURCE_DIR) + "/cases/henann2016/annular_shear.prm";

  struct Point
  {
    double R_i;  // R_i / d
    double rate; // R_i Omega sqrt(rho_s / P_wall)
  };

  /// The finite-difference solution of (92) with the exact Couette kinematics on a 0.01 d grid,
  /// from the case's own physical parameters, at R_i / d = R_i and R_i Omega sqrt(rho_s / P_wall) =
  /// rate.
  postprocess::Nonlocal1dProfile
  reference_solution(const ngf::Parameters &parameters, const double R_i, const double rate)
  {
    const auto                 &m = parameters.material;
    const double                d = m.nonlocal.d;
    postprocess::AnnularShear1d fd;
    fd.material   = m.nonlocal;
    fd.P_wall     = parameters.loading.confining_pressure;
    fd.R_i        = R_i * d;
    fd.R_o        = fd.R_i + parameters.geometry.gap * d;
    fd.h          = 0.01 * d;
    fd.kinematics = postprocess::CouetteKinematics::exact;
    return postprocess::solve_annular_shear_for_speed(
        fd, rate * std::sqrt(fd.P_wall / m.nonlocal.rho_s));
  }

  class AnnularShear : public ::testing::TestWithParam<Point>
  {
  };

  TEST_P(AnnularShear, MatchesTheFiniteDifferenceSolutionOf92)
  {
    const Point        c = GetParam();
    std::ostringstream name;
    name << "ngf_annular_shear_" << c.R_i << "_" << c.rate;
    const auto parameters =
        ngf::load_parameters(case_file, {{"Geometry/Inner radius", std::to_string(c.R_i)},
                                         {"Loading/Wall speed", std::to_string(c.rate)},
                                         {"Output/Reference", "none"},
                                         {"Output/Write vtu", "false"}});
    const auto        summary = test::run_ngf(parameters, name.str());
    const std::string dir     = summary["output_directory"];

    test::expect_matches_reference(summary, dir, reference_solution(parameters, c.R_i, c.rate),
                                   parameters.material.nonlocal.d);
    EXPECT_TRUE(summary["steady_state"]["steady"].get<bool>()) << summary["steady_state"].dump();
    // The one warning allowed is the one on the pressure at the inner wall, which the comment
    // below explains (1.014 P_wall at R_i = 20 d, 1.001 at 100 d).
    for (const auto &w : summary["warnings"])
      EXPECT_EQ(w.get<std::string>().rfind("the mean pressure at the driven wall is", 0), 0U) << w;
  }

  // The FE's mu_wall is the wall's shear stress over the applied P_wall (the paper's definition,
  // from the moment of the inner wall). (92) takes p = P_wall everywhere; in the FE solution the
  // mean pressure p at the inner wall is about 0.5 % higher, and the converged mu_wall sits that
  // much above the value prescribed in the finite-difference solution of (92) (0.3934 at
  // h/d = 1/90, against 0.3913). The local ratio tau / p at the wall, which is what (92)
  // prescribes, matches it: within 0.01 % at h/d = 1/90, and within 0.2 % already at h/d = 1/9,
  // where mu_wall is 0.4 % off.
  TEST(AnnularShearWallStress, LocalStressRatioAtTheWallIsTheFiniteDifferenceMuWall)
  {
    const auto parameters =
        ngf::load_parameters(case_file, {{"Geometry/Inner radius", "60"},
                                         {"Loading/Wall speed", "1e-3"},
                                         {"Geometry/Element size", std::to_string(1. / 9.)},
                                         {"Output/Reference", "none"},
                                         {"Output/Write vtu", "false"}});
    const auto summary = test::run_ngf(parameters, "ngf_annular_shear_wall_stress");

    const auto reference = reference_solution(parameters, 60., 1e-3);

    const double mu_wall = summary["mu_wall"], mu_local = summary["mu_wall_local"];
    const double p_wall  = summary["wall_pressure_over_P_wall"];
    RecordProperty("mu_wall", std::to_string(mu_wall));
    RecordProperty("mu_wall_local", std::to_string(mu_local));
    RecordProperty("wall_pressure_over_P_wall", std::to_string(p_wall));
    RecordProperty("mu_wall_reference", std::to_string(reference.mu_wall));
    EXPECT_GT(p_wall, 1.002) << "the wall pressure exceeds P_wall";
    EXPECT_NE(summary["warnings"].dump().find("the mean pressure at the driven wall is"),
              std::string::npos)
        << "the excess is warned about: " << summary["warnings"].dump();
    EXPECT_NEAR(mu_local, reference.mu_wall, 2e-3 * reference.mu_wall);
    // and its rate-dependent part mu - mu_s, 0.0094 here: -5.6 % at h/d = 1/9 (-23 % at 1/3,
    // -0.3 % at 1/27)
    const double mu_s = parameters.material.nonlocal.mu_s;
    EXPECT_NEAR((mu_local - mu_s) / (reference.mu_wall - mu_s), 1., 0.1);
    EXPECT_LT(std::abs(mu_local - reference.mu_wall), std::abs(mu_wall - reference.mu_wall));
  }

  // Fig. 3b: the rotation rate at R_i / d = 60; Fig. 3d: the inner radius at rate 1e-3.
  INSTANTIATE_TEST_SUITE_P(Rates, AnnularShear,
                           ::testing::Values(Point{60., 1e-4}, Point{60., 1e-2}, Point{60., 1.}),
                           [](const ::testing::TestParamInfo<Point> &info) {
                             return test::test_name("R" + std::to_string(info.param.R_i) + "_rate" +
                                                    std::to_string(info.param.rate));
                           });
  INSTANTIATE_TEST_SUITE_P(Radii, AnnularShear,
                           ::testing::Values(Point{20., 1e-3}, Point{40., 1e-3}, Point{60., 1e-3},
                                             Point{80., 1e-3}, Point{100., 1e-3}),
                           [](const ::testing::TestParamInfo<Point> &info) {
                             return test::test_name("R" + std::to_string(info.param.R_i) + "_rate" +
                                                    std::to_string(info.param.rate));
                           });
} // namespace

namespace
{
  // Henann 6.3, Fig. 7b, on the annulus row: in the rate-independent regime (rate 1e-3) the local
  // model (g = g_loc) collapses the flow into the first element at every resolution, while the
  // nonlocal band keeps its width as the mesh changes (issue #3 f, here without gravity).
  nlohmann::json
  run_annulus(const std::string &fluidity, double h, const std::string &tag)
  {
    const auto parameters =
        ngf::load_parameters(case_file, {{"Solver/Fluidity", fluidity},
                                         {"Geometry/Element size", std::to_string(h)},
                                         {"Output/Reference", "none"},
                                         {"Output/Write vtu", "false"}});
    return test::run_ngf(parameters, "ngf_mesh_" + tag);
  }

  TEST(AnnularShearMeshDependence, LocalModelLocalisesInOneElementNonlocalDoesNot)
  {
    // v / v_wall against r - R_i at the nodes, per mesh; compared at the nodes the meshes share
    // (every grain diameter)
    std::map<double, std::map<long, double>> profile;
    for (const double h : {1., 0.5, 1. / 3.})
      {
        const auto   local = run_annulus("local", h, "local_" + std::to_string(h));
        const double W     = local["shear_band_width_over_d"];
        RecordProperty("local_W_over_d_h" + std::to_string(h), std::to_string(W));
        EXPECT_LT(W, h) << "local model, h/d = " << h
                        << ": the band should lie within the first element";

        const auto   nonlocal = run_annulus("nonlocal", h, "nonlocal_" + std::to_string(h));
        const double Wn       = nonlocal["shear_band_width_over_d"];
        RecordProperty("nonlocal_W_over_d_h" + std::to_string(h), std::to_string(Wn));
        if (h < 0.9)
          {
            EXPECT_GT(Wn, 3. * h) << "the nonlocal band spans several elements at h/d = " << h;
          }
        const auto csv = test::read_csv(nonlocal["output_directory"].get<std::string>() +
                                        "/profiles/velocity.csv");
        for (std::size_t i = 0; i < csv[0].size(); ++i)
          profile[h][std::lround(csv[0][i] * 1e4)] = csv[1][i];
      }
    // over the nodes the two meshes share (every grain diameter: 21 across the gap of 20 d)
    auto difference = [&](double h) {
      double      worst  = 0.;
      std::size_t shared = 0;
      for (const auto &[x, v] : profile[h])
        if (const auto fine = profile[1. / 3.].find(x); fine != profile[1. / 3.].end())
          {
            worst = granflow::max_abs(worst, v - fine->second);
            ++shared;
          }
      EXPECT_GE(shared, 21u) << "h/d = " << h << ": too few nodes shared with h/d = 1/3";
      return worst;
    };
    RecordProperty("nonlocal_profile_difference_h1_vs_h1/3", std::to_string(difference(1.)));
    RecordProperty("nonlocal_profile_difference_h1/2_vs_h1/3", std::to_string(difference(0.5)));
    // Fig. 7b's criterion (0.02 of the wall speed) holds between h/d = 1/2 and 1/3; h/d = 1, with
    // two elements across the band, differs by about 0.09 (reported, not asserted).
    EXPECT_LE(difference(0.5), 0.02);
  }
} // namespace
