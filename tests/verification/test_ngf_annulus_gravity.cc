// Henann & Kamrin 2016, 6.3: the annulus with gravity (the quad section) against an independent
// reference. Where the flow is rate-independent, the steady solution of (92) scaled by the wall
// speed does not depend on the pressure. Every depth can then carry the same profile: the fluidity
// does not vary with depth, so its vertical diffusion in (23) vanishes, and no torque passes
// between depths (tau_z theta = 0), so the moment balance of each depth gives it the shear stress
// tau_wall (R_i / r)^2 of 6.2 at its hydrostatic pressure phi rho_s G (H - Z). Each depth is then
// the 1D reduction (92) at its own pressure. This is an asymptotic reference, not an exact one. The
// test computes that reduction by finite differences on a 0.01 d grid (exact Couette kinematics,
// the same inner and outer radii and wall speed) at six depths and compares the case's
// profiles/velocity_at_depth_*.csv with it: v / v_wall within 0.03 at every node and W / d
// within 5 %, the tolerances of issue #3 b. Measured: 0.0099 and 1.6 % at most (the annulus row
// of 6.2 on the same radial mesh differs from (92) by 0.0088). Weighting the element's volume by
// sqrt(R) instead of R (a moment balance tau ~ r^-1.5) fails it at five of the six depths (W 4 to
// 6 % off). A reduced cell keeps it fast:
// R_i = 20 d, R_o - R_i = 6 d, H = 3 d, h = d / 3, 2 degrees at R_i Omega / sqrt(G d) = 1e-3.
// Since the profile is pressure-independent, this checks the flow (the generalized-axisymmetric
// element with its twist, the fluidity, their coupling under a depth-dependent pressure), not the
// magnitude of gravity.
#include "models/ngf/ngf_model.h"
#include "postprocess/nonlocal_1d.h"
#include "support/csv.h"
#include "support/ngf_run.h"
#include "support/reference_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace
{
  using namespace granflow;

  TEST(AnnulusWithGravity, EveryDepthFlowsLikeTheReduction92AtItsPressure)
  {
    const std::vector<double> depths = {0.5, 1., 1.5, 2., 2.5, 3.}; // in d; 3 is the floor
    const std::string         case_file =
        std::string(GRANFLOW_SOURCE_DIR) + "/cases/henann2016/annular_shear_gravity.prm";
    const auto parameters =
        ngf::load_parameters(case_file, {{"Geometry/Inner radius", "20"},
                                         {"Geometry/Gap", "6"},
                                         {"Geometry/Height", "3"},
                                         {"Geometry/Element size", "0.333333333333"},
                                         {"Loading/Wall rotation", "2"},
                                         {"Output/Profile depths", "0.5, 1, 1.5, 2, 2.5, 3"},
                                         {"Output/Write vtu", "false"}});
    const auto        summary = test::run_ngf(parameters, "ngf_annulus_gravity_depths");
    const std::string dir     = summary["output_directory"];
    EXPECT_TRUE(summary["steady_state"]["steady"].get<bool>()) << summary["steady_state"].dump();
    EXPECT_TRUE(summary["warnings"].empty()) << summary["warnings"].dump();
    ASSERT_EQ(summary["profiles_at_depth"].size(), depths.size());

    const auto  &m = parameters.material;
    const double d = m.nonlocal.d;
    for (std::size_t k = 0; k < depths.size(); ++k)
      {
        const auto &entry = summary["profiles_at_depth"][k];
        ASSERT_DOUBLE_EQ(entry["depth_over_d"].get<double>(), depths[k]);
        postprocess::AnnularShear1d fd;
        fd.material          = m.nonlocal;
        fd.P_wall            = m.phi * m.nonlocal.rho_s * m.G * depths[k] * d; // hydrostatic (27)
        fd.R_i               = parameters.geometry.inner_radius * d;
        fd.R_o               = fd.R_i + parameters.geometry.gap * d;
        fd.h                 = 0.01 * d;
        fd.kinematics        = postprocess::CouetteKinematics::exact;
        const auto reference = postprocess::solve_annular_shear_for_speed(
            fd, parameters.loading.wall_speed * std::sqrt(m.G * d));

        const auto profile = test::read_csv(dir + "/" + entry["file"].get<std::string>());
        ASSERT_GE(profile.size(), 2U);
        const double worst =
            test::max_difference_to_reference(profile[0], profile[1], reference, d);
        const double      W    = entry["shear_band_width_over_d"];
        const double      W_fd = reference.shear_band_width / d;
        const std::string at   = "depth_" + ngf::profile_depth_name(depths[k]);
        RecordProperty(at + "_max_velocity_difference", std::to_string(worst));
        RecordProperty(at + "_W_over_d", std::to_string(W) + " (FD " + std::to_string(W_fd) + ")");
        EXPECT_LE(worst, 0.03) << "at depth " << depths[k] << " d";
        EXPECT_NEAR(W, W_fd, 0.05 * W_fd) << "at depth " << depths[k] << " d";
      }
  }
} // namespace
