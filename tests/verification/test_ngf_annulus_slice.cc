// Henann & Kamrin 2016, 6.3: the annulus with gravity computed two ways, on the generalized-
// axisymmetric quad section and on a 3D slice of bricks with rotated periodic faces, must give the
// same flow (the paper: "indistinguishable"). A reduced cell keeps the test fast: R_i = 20 d,
// R_o - R_i = 6 d, H = 3 d, h/d = 1/2, 2 degrees of rotation at R_i Omega / sqrt(G d) = 1e-3.
// Checked: surface velocity within 0.02 of the wall speed (issue #3 c), W within 1 % and mu_wall
// within 1.5 % (measured 0.31 % and 0.66 %).
#include "core/max_abs.h"
#include "models/ngf/ngf_model.h"
#include "support/csv.h"
#include "support/ngf_run.h"

#include <gtest/gtest.h>

#include <cmath>

namespace
{
  using namespace granflow;

  nlohmann::json
  run_cell(const std::string &case_name)
  {
    const std::string case_file =
        std::string(GRANFLOW_SOURCE_DIR) + "/cases/henann2016/" + case_name + ".prm";
    const auto parameters = ngf::load_parameters(case_file, {{"Geometry/Inner radius", "20"},
                                                             {"Geometry/Gap", "6"},
                                                             {"Geometry/Height", "3"},
                                                             {"Geometry/Element size", "0.5"},
                                                             {"Loading/Wall rotation", "2"},
                                                             {"Output/Write vtu", "false"}});
    return test::run_ngf(parameters, "ngf_" + case_name);
  }

  TEST(AnnulusWithGravity, QuadSectionAndThreeDimensionalSliceAgree)
  {
    const auto        quad      = run_cell("annular_shear_gravity");
    const auto        slice     = run_cell("annular_shear_gravity_slice");
    const std::string quad_dir  = quad["output_directory"];
    const std::string slice_dir = slice["output_directory"];

    const auto a = test::read_csv(quad_dir + "/profiles/velocity.csv");
    const auto b = test::read_csv(slice_dir + "/profiles/velocity.csv");
    ASSERT_EQ(a[0].size(), b[0].size());
    double worst = 0.;
    for (std::size_t i = 0; i < a[0].size(); ++i)
      {
        ASSERT_NEAR(a[0][i], b[0][i], 1e-9); // the same surface nodes
        worst = granflow::max_abs(worst, a[1][i] - b[1][i]);
      }
    RecordProperty("max_surface_velocity_difference", std::to_string(worst));
    EXPECT_LE(worst, 0.02); // the bound (#3 c)
    // ... and a regression bound, 3 times what was measured here (0.0019): a drift like the full
    // case's slice after 8 degrees (0.019, docs/ngf.md) would pass the bound
    EXPECT_LE(worst, 6e-3);
    const double W_quad  = quad["shear_band_width_over_d"],
                 W_slice = slice["shear_band_width_over_d"];
    const double mu_quad = quad["mu_wall"], mu_slice = slice["mu_wall"];
    RecordProperty("W_relative_difference", std::to_string(W_slice / W_quad - 1.));
    RecordProperty("mu_wall_relative_difference", std::to_string(mu_slice / mu_quad - 1.));
    EXPECT_NEAR(W_slice, W_quad, 0.01 * W_quad);
    EXPECT_NEAR(mu_slice, mu_quad, 0.015 * mu_quad);
  }
} // namespace
