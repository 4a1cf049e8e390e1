// Unit tests of the finite-difference references src/postprocess/nonlocal_1d.h for Henann & Kamrin
// 2016, Section 6.1 (90) and 6.2 (92): second-order convergence of the fluidity operator against
// manufactured solutions (cartesian and cylindrical), the local limit g -> g_loc (small A), the
// closed form of homogeneous shear (no gravity: constant g, linear v), the speed shooting, and the
// paper's observations (mu_wall -> mu_s and the rate-independent plateau of W at low speed).
#include "core/max_abs.h"
#include "postprocess/nonlocal_1d.h"
#include "support/reference_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace
{
  using namespace granflow;
  using namespace granflow::postprocess;

  constexpr double pi = 3.14159265358979323846;

  // Paper parameters (Henann 6): the NonlocalParameters defaults, spelled out so that a change of
  // the defaults does not silently change these tests.
  rheology::NonlocalParameters
  paper_material()
  {
    rheology::NonlocalParameters m;
    m.mu_s  = 0.3819;
    m.b     = 0.9377;
    m.A     = 0.48;
    m.d     = 1e-3;
    m.rho_s = 2450.;
    return m;
  }

  // 6.1: P_wall / (phi rho_s G d) = 6.67, depth 20 d, h = 0.01 d.
  LinearShearGravity1d
  paper_linear_shear()
  {
    LinearShearGravity1d problem;
    problem.material = paper_material();
    problem.phi      = 0.62;
    problem.G        = 9.81;
    const double d   = problem.material.d;
    problem.P_wall   = 6.67 * problem.phi * problem.material.rho_s * problem.G * d;
    problem.depth    = 20. * d;
    problem.h        = 0.01 * d;
    return problem;
  }

  // 6.2: R_i = 60 d, R_o = R_i + 20 d, h = 0.01 d.
  AnnularShear1d
  paper_annular_shear(const CouetteKinematics kinematics)
  {
    AnnularShear1d problem;
    problem.material   = paper_material();
    const double d     = problem.material.d;
    problem.P_wall     = 1000.;
    problem.R_i        = 60. * d;
    problem.R_o        = problem.R_i + 20. * d;
    problem.h          = 0.01 * d;
    problem.kinematics = kinematics;
    return problem;
  }

  double
  linear_shear_speed_scale(const LinearShearGravity1d &problem)
  {
    return std::sqrt(problem.G * problem.material.d); // sqrt(G d)
  }

  double
  annular_speed_scale(const AnnularShear1d &problem)
  {
    return std::sqrt(problem.P_wall / problem.material.rho_s); // R_i Omega sqrt(rho_s / P_wall) = 1
  }

  // ----- (1) the discrete operator against manufactured solutions
  // g = 2 + cos(k (x - a)), k = pi / (b - a), has g' = 0 at both ends; with a given xi(x) the
  // source g_loc = g - xi^2 L g makes it the exact solution of L g - g / xi^2 = -g_loc / xi^2.
  struct Manufactured
  {
    double a, b;
    bool   variable_xi;

    double
    k() const
    {
      return pi / (b - a);
    }
    double
    g(const double x) const
    {
      return 2. + std::cos(k() * (x - a));
    }
    double
    xi(const double x) const
    {
      return variable_xi ? 0.2 + 0.1 * (x - a) / (b - a) : 0.3;
    }
    double
    operator_of_g(const double x, const Coordinates1d c) const
    {
      const double gpp = -k() * k() * std::cos(k() * (x - a));
      const double gp  = -k() * std::sin(k() * (x - a));
      return c == Coordinates1d::cylindrical ? gpp + gp / x : gpp;
    }
  };

  double
  max_error(const Manufactured &problem, const Coordinates1d c, const std::size_t n_intervals)
  {
    std::vector<double> x(n_intervals + 1), xi(x.size()), g_loc(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      {
        x[i]     = problem.a + (problem.b - problem.a) * double(i) / double(n_intervals);
        xi[i]    = problem.xi(x[i]);
        g_loc[i] = problem.g(x[i]) - xi[i] * xi[i] * problem.operator_of_g(x[i], c);
      }
    const std::vector<double> g = solve_fluidity_fd(x, xi, g_loc, c);
    double                    e = 0.;
    for (std::size_t i = 0; i < x.size(); ++i)
      e = granflow::max_abs(e, g[i] - problem.g(x[i]));
    return e;
  }

  void
  expect_second_order(const Manufactured &problem, const Coordinates1d c, const char *name)
  {
    std::vector<double> errors;
    for (std::size_t n = 20; n <= 640; n *= 2)
      errors.push_back(max_error(problem, c, n));
    for (std::size_t j = 0; j + 1 < errors.size(); ++j)
      {
        const double order = std::log2(errors[j] / errors[j + 1]);
        EXPECT_GE(order, 1.8) << name << " refinement " << j;
        EXPECT_LE(order, 2.2) << name << " refinement " << j;
      }
    std::cout << name << ": max error on 20 ... 640 intervals:";
    for (const double e : errors)
      std::cout << ' ' << std::setprecision(3) << e;
    std::cout << '\n';
  }

  TEST(FluidityOperator, CartesianSecondOrderConstantXi)
  {
    expect_second_order({0., 1., false}, Coordinates1d::cartesian, "cartesian, constant xi");
  }

  TEST(FluidityOperator, CartesianSecondOrderVariableXi)
  {
    expect_second_order({0., 1., true}, Coordinates1d::cartesian, "cartesian, variable xi");
  }

  TEST(FluidityOperator, CylindricalSecondOrderConstantXi)
  {
    // R_i = 0.5 (R_o - R_i): the 1/r term is as large as g'' near the inner wall.
    expect_second_order({0.5, 1.5, false}, Coordinates1d::cylindrical, "cylindrical, constant xi");
  }

  TEST(FluidityOperator, CylindricalSecondOrderVariableXi)
  {
    expect_second_order({0.5, 1.5, true}, Coordinates1d::cylindrical, "cylindrical, variable xi");
  }

  TEST(FluidityOperator, RejectsBadGrids)
  {
    const std::vector<double> three(3, 1.);
    EXPECT_THROW(solve_fluidity_fd({0., 1.}, {1., 1.}, {1., 1.}, Coordinates1d::cartesian),
                 std::invalid_argument);
    EXPECT_THROW(solve_fluidity_fd({0., 1., 3.}, three, three, Coordinates1d::cartesian),
                 std::invalid_argument);
    EXPECT_THROW(solve_fluidity_fd({0., 1., 2.}, three, three, Coordinates1d::cylindrical),
                 std::invalid_argument);
    EXPECT_THROW(solve_fluidity_fd({1., 2., 3.}, {1., 0., 1.}, three, Coordinates1d::cartesian),
                 std::invalid_argument);
  }

  // ----- (2) local limit and homogeneous shear
  TEST(AnnularShear, SmallAGivesLocalFluidity)
  {
    // A = 1e-4 makes xi ~ 1e-4 d where mu - mu_s = O(0.1): (92) reduces to g = g_loc except in
    // boundary layers of a few xi at the walls, where g_loc' != 0 meets g' = 0.
    AnnularShear1d problem = paper_annular_shear(CouetteKinematics::exact);
    problem.material.A     = 1e-4;
    const double mu_wall   = 0.9; // mu(R_o) = 0.9 (60/80)^2 = 0.51 > mu_s: flowing everywhere
    const Nonlocal1dProfile profile = solve_annular_shear(problem, mu_wall);
    double                  g_max = 0., deviation = 0.;
    for (std::size_t i = 0; i < profile.x.size(); ++i)
      {
        const double g_loc =
            rheology::local_fluidity(profile.p[i], profile.mu[i], problem.material).value;
        g_max = std::max(g_max, g_loc);
        if (profile.x[i] - problem.R_i > 0.1 * problem.material.d &&
            problem.R_o - profile.x[i] > 0.1 * problem.material.d)
          deviation = granflow::max_abs(deviation, profile.g[i] - g_loc);
      }
    EXPECT_LT(deviation / g_max, 1e-6);
    std::cout << "local limit: max |g - g_loc| / max g_loc = " << deviation / g_max << '\n';

    // With the paper's A = 0.48 the nonlocal term is not negligible: the check above can fail.
    problem.material.A                         = 0.48;
    const Nonlocal1dProfile nonlocal           = solve_annular_shear(problem, mu_wall);
    double                  nonlocal_deviation = 0.;
    for (std::size_t i = 0; i < nonlocal.x.size(); ++i)
      if (nonlocal.x[i] - problem.R_i > 0.1 * problem.material.d &&
          problem.R_o - nonlocal.x[i] > 0.1 * problem.material.d)
        nonlocal_deviation = std::max(
            nonlocal_deviation,
            std::abs(
                nonlocal.g[i] -
                rheology::local_fluidity(nonlocal.p[i], nonlocal.mu[i], problem.material).value));
    EXPECT_GT(nonlocal_deviation / g_max, 1e-3);
  }

  TEST(AnnularShear, LocalLimitVelocityMatchesQuadrature)
  {
    // In the local limit gamma_dot = g_loc(P_wall, mu(r)) mu(r) is known in closed form, so the
    // wall speed follows from a fine composite Simpson rule, independently of the trapezoidal sums:
    // exact kinematics R_i int gamma_dot / r dr, the paper's int gamma_dot dr (over [R_i, R_o]).
    // The trapezoidal error at h = 0.01 d is ~(h / R_i)^2 ~ 3e-8.
    for (const auto kinematics : {CouetteKinematics::exact, CouetteKinematics::paper_dv_dr})
      {
        AnnularShear1d problem = paper_annular_shear(kinematics);
        problem.material.A     = 1e-4;
        const double mu_wall   = 0.9;
        const bool   exact     = kinematics == CouetteKinematics::exact;
        auto         integrand = [&](const double r) {
          const double mu = mu_wall * std::pow(problem.R_i / r, 2);
          const double gamma_dot =
              rheology::local_fluidity(problem.P_wall, mu, problem.material).value * mu;
          return exact ? problem.R_i * gamma_dot / r : gamma_dot;
        };
        const std::size_t n   = 20000; // even
        const double      h   = (problem.R_o - problem.R_i) / double(n);
        double            sum = integrand(problem.R_i) + integrand(problem.R_o);
        for (std::size_t i = 1; i < n; ++i)
          sum += (i % 2 ? 4. : 2.) * integrand(problem.R_i + double(i) * h);
        const double v_wall = sum * h / 3.;
        const double fd     = solve_annular_shear(problem, mu_wall).v_wall;
        EXPECT_NEAR(fd / v_wall, 1., 1e-6) << (exact ? "exact" : "paper_dv_dr");
      }
  }

  TEST(LinearShear, WithoutGravityIsHomogeneousSimpleShear)
  {
    // G = 0: p and mu are uniform, so g = g_loc exactly (Neumann, constant source) and
    // v = g mu (depth - z) is linear, integrated exactly by the trapezoidal rule.
    LinearShearGravity1d problem    = paper_linear_shear();
    problem.G                       = 0.;
    problem.h                       = 0.1 * problem.material.d;
    const double            mu_wall = 0.5;
    const Nonlocal1dProfile profile = solve_linear_shear_gravity(problem, mu_wall);
    const double g_loc = rheology::local_fluidity(problem.P_wall, mu_wall, problem.material).value;
    ASSERT_GT(g_loc, 0.);
    for (std::size_t i = 0; i < profile.x.size(); ++i)
      {
        EXPECT_NEAR(profile.g[i], g_loc, 1e-12 * g_loc);
        EXPECT_NEAR(profile.v[i], g_loc * mu_wall * (problem.depth - profile.x[i]),
                    1e-11 * g_loc * mu_wall * problem.depth);
      }
    EXPECT_NEAR(profile.shear_band_width, problem.depth * (1. - std::exp(-1.)),
                1e-9 * problem.depth);
  }

  TEST(LinearShear, BelowYieldNothingFlows)
  {
    const Nonlocal1dProfile profile = solve_linear_shear_gravity(paper_linear_shear(), 0.3);
    EXPECT_EQ(profile.v_wall, 0.);
    EXPECT_TRUE(std::isnan(profile.shear_band_width));
  }

  TEST(Nonlocal1d, RejectsBadInput)
  {
    LinearShearGravity1d linear = paper_linear_shear();
    linear.h                    = 0.;
    EXPECT_THROW(solve_linear_shear_gravity(linear, 0.4), std::invalid_argument);
    linear       = paper_linear_shear();
    linear.depth = -1.;
    EXPECT_THROW(solve_linear_shear_gravity(linear, 0.4), std::invalid_argument);
    EXPECT_THROW(solve_linear_shear_gravity_for_speed(paper_linear_shear(), 0.),
                 std::invalid_argument);
    EXPECT_THROW(solve_linear_shear_gravity(paper_linear_shear(), -0.1), std::invalid_argument);

    AnnularShear1d annular = paper_annular_shear(CouetteKinematics::exact);
    annular.R_o            = annular.R_i;
    EXPECT_THROW(solve_annular_shear(annular, 0.4), std::invalid_argument);
    annular   = paper_annular_shear(CouetteKinematics::exact);
    annular.h = -1e-5;
    EXPECT_THROW(solve_annular_shear(annular, 0.4), std::invalid_argument);
    EXPECT_THROW(solve_annular_shear_for_speed(paper_annular_shear(CouetteKinematics::exact), -1.),
                 std::invalid_argument);
    try
      {
        solve_annular_shear(annular, 0.4);
      }
    catch (const std::invalid_argument &e)
      {
        EXPECT_NE(std::string(e.what()).find("grid step h"), std::string::npos) << e.what();
      }
  }

  TEST(LinearShear, SecondOrderInTheGridStep)
  {
    // Whole pipeline (g, gamma_dot, trapezoidal v) at a fixed mu_wall of the rate-independent
    // regime (v_wall / sqrt(G d) ~ 1e-3): v_wall converges at second order. The source lives in a
    // layer of only 0.3 d where mu > mu_s and v_wall ~ (mu_wall - mu_s)^3, so h = 0.01 d leaves
    // ~6e-4 of v_wall (2e-4 of mu_wall - mu_s, 3e-6 in mu_wall), still far below FE errors.
    LinearShearGravity1d problem = paper_linear_shear();
    const double         d       = problem.material.d;
    const double         mu_wall = 0.3988;
    std::vector<double>  v_wall;
    for (const double h : {0.04, 0.02, 0.01})
      {
        problem.h = h * d;
        v_wall.push_back(solve_linear_shear_gravity(problem, mu_wall).v_wall);
      }
    const double order = std::log2((v_wall[0] - v_wall[1]) / (v_wall[1] - v_wall[2]));
    EXPECT_GE(order, 1.8);
    EXPECT_LE(order, 2.2);
    const double error_at_paper_h = std::abs(v_wall[1] - v_wall[2]) / 3. / v_wall[2];
    EXPECT_LT(error_at_paper_h, 1e-3);
    std::cout << "linear shear, mu_wall = " << mu_wall << ": observed order " << order
              << ", estimated relative error of v_wall at h = 0.01 d: " << error_at_paper_h << '\n';
  }

  // ----- (3) speed shooting
  TEST(LinearShear, ShootingReproducesWallSpeed)
  {
    const LinearShearGravity1d problem = paper_linear_shear();
    for (const double rate : {1e-4, 1e-2, 1.})
      {
        const double            target  = rate * linear_shear_speed_scale(problem);
        const Nonlocal1dProfile profile = solve_linear_shear_gravity_for_speed(problem, target);
        EXPECT_NEAR(profile.v_wall / target, 1., 1e-9) << "v_wall / sqrt(G d) = " << rate;
        std::cout << "linear shear rate " << rate
                  << ": |v_wall / target - 1| = " << std::abs(profile.v_wall / target - 1.) << '\n';
        // Independently of the shooting: force control at the returned mu_wall gives that speed.
        const Nonlocal1dProfile again = solve_linear_shear_gravity(problem, profile.mu_wall);
        EXPECT_NEAR(again.v_wall / target, 1., 1e-9) << "v_wall / sqrt(G d) = " << rate;
        EXPECT_EQ(profile.v.back(), 0.);
      }
  }

  // The steady Galerkin reduction of (34) converges to the FD solution of (90) as the elements
  // shrink (measured: 0.0515, 0.0091, 0.0010 of v_wall at h/d = 1, 1/3, 1/9, about second
  // order), reproduces the wall speed, and at h/d = 1/9 has the FD's band width (0.04 %) and
  // mu_wall (0.12 %).
  TEST(LinearShear, GalerkinReductionConvergesToTheFiniteDifferenceSolution)
  {
    const LinearShearGravity1d problem = paper_linear_shear();
    const double               d       = problem.material.d;
    const double               v_wall  = 1e-3 * linear_shear_speed_scale(problem);
    const Nonlocal1dProfile    fd      = solve_linear_shear_gravity_for_speed(problem, v_wall);
    std::vector<double>        error;
    for (const unsigned int n : {20U, 60U, 180U}) // h/d = 1, 1/3, 1/9
      {
        const Nonlocal1dProfile g = solve_linear_shear_gravity_galerkin(problem, n, v_wall, fd);
        EXPECT_NEAR(g.v_wall / v_wall, 1., 1e-9);
        const double worst = test::max_difference_to_reference(g, fd, d);
        error.push_back(worst);
        std::cout << "Galerkin reduction, h/d = " << 20. / n
                  << ": max |v - v_FD| / v_wall = " << worst << ", mu_wall " << g.mu_wall << " (FD "
                  << fd.mu_wall << "), W/d " << g.shear_band_width / d << " (FD "
                  << fd.shear_band_width / d << ")\n";
        if (n == 180U)
          {
            EXPECT_NEAR(g.mu_wall, fd.mu_wall, 2e-3 * fd.mu_wall);
            EXPECT_NEAR(g.shear_band_width, fd.shear_band_width, 0.005 * fd.shear_band_width);
          }
      }
    EXPECT_GT(error[0], 0.04); // h = d: the method's own coarse-mesh error
    EXPECT_LT(error[1], error[0] / 4.);
    EXPECT_LT(error[2], error[1] / 4.);
    EXPECT_LT(error[2], 0.002);
  }

  TEST(AnnularShear, ShootingReproducesWallSpeed)
  {
    for (const auto kinematics : {CouetteKinematics::exact, CouetteKinematics::paper_dv_dr})
      {
        const AnnularShear1d problem = paper_annular_shear(kinematics);
        for (const double rate : {1e-4, 1e-2, 1.})
          {
            const double            target  = rate * annular_speed_scale(problem);
            const Nonlocal1dProfile profile = solve_annular_shear_for_speed(problem, target);
            EXPECT_NEAR(profile.v_wall / target, 1., 1e-9) << "R_i Omega sqrt(rho_s/P) = " << rate;
            std::cout << "annular shear rate " << rate
                      << ": |v_wall / target - 1| = " << std::abs(profile.v_wall / target - 1.)
                      << '\n';
            const Nonlocal1dProfile again = solve_annular_shear(problem, profile.mu_wall);
            EXPECT_NEAR(again.v_wall / target, 1., 1e-9) << "R_i Omega sqrt(rho_s/P) = " << rate;
          }
      }
  }

  // ----- (4) the paper's observations
  // mu_wall and W over the wall speeds of the insets of Figs. 1(b,c) and 3(b,c): mu_wall decreases
  // to mu_s and W to a plateau as the speed drops; W grows with the speed from 1e-3 to 1.
  // mu_wall - mu_s vanishes only like v_wall^(1/3) (g_loc, xi^-2 and the thickness of the layer
  // where mu > mu_s are each proportional to mu_wall - mu_s), so mu_wall is within 1% of mu_s only
  // below about 1e-5, not at 1e-4 (2.1% for linear shear, 1.2% for the annulus).
  template <typename Solve>
  void
  expect_paper_trends(const Solve &solve, const double mu_s, const double d, const char *name,
                      const double max_excess_at_1e_4)
  {
    const std::vector<double> rates = {1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.};
    std::vector<double>       excess, widths, v_walls;
    for (const double rate : rates)
      {
        const Nonlocal1dProfile profile = solve(rate);
        excess.push_back(profile.mu_wall / mu_s - 1.);
        widths.push_back(profile.shear_band_width / d);
        v_walls.push_back(profile.v_wall);
        std::ostringstream line;
        line << name << " rate " << rate << ": W/d = " << std::setprecision(5) << widths.back()
             << ", mu_wall = " << std::setprecision(8) << profile.mu_wall
             << ", mu_wall/mu_s - 1 = " << std::setprecision(4) << excess.back();
        if (excess.size() > 1)
          line << ", d log v_wall / d log(mu_wall - mu_s) = "
               << std::log(v_walls.back() / v_walls[v_walls.size() - 2]) /
                      std::log(excess.back() / excess[excess.size() - 2]);
        std::cout << line.str() << '\n';
        ::testing::Test::RecordProperty(std::string(name) + "_rate_" + std::to_string(rate),
                                        line.str());
      }
    for (std::size_t j = 0; j + 1 < rates.size(); ++j)
      EXPECT_LT(excess[j], excess[j + 1]) << name << " rate " << rates[j];
    EXPECT_GT(excess.front(), 0.) << name;
    EXPECT_LT(excess.front(), 0.01) << name << ": mu_wall -> mu_s at rate 1e-6";
    EXPECT_LT(excess[2], max_excess_at_1e_4) << name << ": mu_wall at rate 1e-4";
    for (std::size_t j = 3; j + 1 < rates.size(); ++j)
      EXPECT_LT(widths[j], widths[j + 1]) << name << " rate " << rates[j];
  }

  TEST(LinearShear, PaperTrends)
  {
    const LinearShearGravity1d problem = paper_linear_shear();
    expect_paper_trends(
        [&](const double rate) {
          return solve_linear_shear_gravity_for_speed(problem,
                                                      rate * linear_shear_speed_scale(problem));
        },
        problem.material.mu_s, problem.material.d, "linear_shear", 0.025);
  }

  TEST(AnnularShear, PaperTrends)
  {
    const AnnularShear1d problem = paper_annular_shear(CouetteKinematics::exact);
    expect_paper_trends(
        [&](const double rate) {
          return solve_annular_shear_for_speed(problem, rate * annular_speed_scale(problem));
        },
        problem.material.mu_s, problem.material.d, "annular_shear_exact", 0.015);
  }

  TEST(AnnularShear, ExactCouetteKinematicsDifferFromPaperDvDr)
  {
    // Same wall speed, R_i / d = 60, R_i Omega sqrt(rho_s / P_wall) = 1e-3 (Fig. 3(d)).
    const AnnularShear1d    exact  = paper_annular_shear(CouetteKinematics::exact);
    const AnnularShear1d    paper  = paper_annular_shear(CouetteKinematics::paper_dv_dr);
    const double            target = 1e-3 * annular_speed_scale(exact);
    const Nonlocal1dProfile a      = solve_annular_shear_for_speed(exact, target);
    const Nonlocal1dProfile b      = solve_annular_shear_for_speed(paper, target);
    ASSERT_EQ(a.x.size(), b.x.size());
    double difference = 0.;
    for (std::size_t i = 0; i < a.x.size(); ++i)
      difference = granflow::max_abs(difference, (a.v[i] - b.v[i]) / target);
    std::ostringstream line;
    line << "annular R_i/d = 60, rate 1e-3: max |v_exact - v_paper| / v_wall = "
         << std::setprecision(4) << difference << "; W/d exact "
         << a.shear_band_width / exact.material.d << " paper "
         << b.shear_band_width / paper.material.d << "; mu_wall exact " << std::setprecision(8)
         << a.mu_wall << " paper " << b.mu_wall;
    std::cout << line.str() << '\n';
    RecordProperty("couette_exact_vs_paper", line.str());
    // r int gamma / r' differs from int gamma by O(W / R_i) = 4%, but at the same v_wall most of
    // that cancels in the shape: what remains (0.26%) is small, yet far above the discretisation
    // error (~1e-4 at h = 0.01 d).
    EXPECT_GT(difference, 1e-3);
    EXPECT_LT(difference, 1e-2); // measured 0.0026
  }
} // namespace

TEST(ShearBandWidth, FirstCrossingOfVWallOverELinearBetweenNodes)
{
  using granflow::postprocess::shear_band_width;
  const double v_e = std::exp(-1.);
  // v = 1 - x / 2 on x in [1, 3] (x.front() = 1): v = 1/e at x - 1 = 2 (1 - 1/e)
  EXPECT_NEAR(shear_band_width({1., 2., 3.}, {1., 0.5, 0.}, 1.), 2. * (1. - v_e), 1e-15);
  // the first crossing counts, not a later one after a rise
  EXPECT_NEAR(shear_band_width({0., 1., 2., 3.}, {2., 0., 2., 0.}, 2.), 1. - v_e, 1e-15);
  EXPECT_TRUE(std::isnan(shear_band_width({0., 1.}, {1., 0.9}, 1.))); // never decays
  EXPECT_TRUE(std::isnan(shear_band_width({0., 1.}, {0., 0.}, 0.)));  // nothing flows
}
