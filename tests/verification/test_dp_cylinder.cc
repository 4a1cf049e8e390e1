// Daviet & Bertails-Descoubes 2016, 6.3.2 (Fig. 14): granular flow around a cylinder (mu = 0.3,
// Re = 100, D = L/4). Dilatancy is what makes the wake well defined: behind the cylinder the
// pressure vanishes and the flow dilates (div u > 0), where an incompressible model would need a
// negative pressure. The drag F_D = int lambda n . e_x is positive (along the flow).
#include "core/output.h"
#include "models/dp/dp_model.h"

#include <gtest/gtest.h>

#include <filesystem>

TEST(CylinderFlow, WakeHasZeroPressureAndDilatesAndDragIsReported)
{
  const std::string case_file = std::string(GRANFLOW_SOURCE_DIR) + "/cases/daviet2016/cylinder.prm";
  const auto        parameters = granflow::dp::load_parameters(case_file, {{"Output/Write vtu", "false"}});
  const std::string dir        = ::testing::TempDir() + "/granflow_cylinder";
  std::filesystem::remove_all(dir);
  granflow::OutputDirectory out(dir);
  granflow::Logger          log(out.file("log.txt"), false);
  const auto                s = granflow::dp::run(parameters, out, log).summary;

  ASSERT_TRUE(s["solver"]["converged"].get<bool>());
  ASSERT_GT(s["wake"]["points"].get<int>(), 100);
  EXPECT_EQ(s["wake"]["max_pressure"].get<double>(), 0.);
  EXPECT_GT(s["wake"]["min_div_u"].get<double>(), 0.);
  EXPECT_GT(s["pressure"]["max"].get<double>(), 0.);
  EXPECT_GT(s["drag"].get<double>(), 0.);
  EXPECT_GT(s["U_infinity"].get<double>(), 0.);
  EXPECT_NEAR(s["drag_coefficient"].get<double>(),
              s["drag"].get<double>() /
                (0.5 * s["U_infinity"].get<double>() * s["U_infinity"].get<double>() * 0.25),
              1e-12);
}
