// Cadoux fixed point + PG / APGD / SPG or interior-point steps, and the interior-point method, on
// cone problems with a known solution.
#include "rheology/drucker_prager.h"
#include "solvers/cholmod_solver.h"
#include "solvers/cone_problem.h"
#include "solvers/dense.h"
#include "solvers/interior_point_loop.h" // detail::norm_inf
#include "solvers/soc.h"
#include "solvers/solve_monitor.h"
#include "solvers/umfpack_solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <numeric>
#include <random>
#include <regex>
#include <sstream>
#include <tuple>

using namespace granflow::solvers;

namespace
{
  CsrMatrix
  dense_to_csr(const std::vector<std::vector<double>> &M)
  {
    CsrMatrix A;
    A.n_rows = M.size();
    A.n_cols = M.empty() ? 0 : M[0].size();
    A.row_start.push_back(0);
    for (const auto &row : M)
      {
        for (std::size_t j = 0; j < row.size(); ++j)
          if (row[j] != 0.)
            {
              A.column.push_back(static_cast<int>(j));
              A.value.push_back(row[j]);
            }
        A.row_start.push_back(static_cast<int>(A.column.size()));
      }
    return A;
  }

  std::vector<std::vector<double>>
  identity(std::size_t n)
  {
    std::vector<std::vector<double>> I(n, std::vector<double>(n, 0.));
    for (std::size_t i = 0; i < n; ++i)
      I[i][i] = 1.;
    return I;
  }

  /// One constraint point with A = H = I, l = w and k = 0 (block size w.size()): then gamma = u =
  /// lambda + w, and lambda is the single-point solution for w.
  ConeProblemData
  single_point_problem(const std::vector<double> &w, const double mu, const double Bi)
  {
    ConeProblemData data;
    data.block_size = w.size();
    data.A          = dense_to_csr(identity(w.size()));
    data.H          = dense_to_csr(identity(w.size()));
    data.l          = w;
    data.k.assign(w.size(), 0.);
    data.mu = {mu};
    data.Bi = {Bi};
    return data;
  }

  /// A random SPD A (n dofs) and a random H coupling 3 points with blocks of `block_size` (3: 2D,
  /// 6: 3D), mu = 0.3, 0.5, 0.8, Bi = 0.
  ConeProblemData
  coupled_random_problem(const std::size_t block_size = 3, const std::size_t n = 10)
  {
    std::mt19937                           rng(11);
    std::uniform_real_distribution<double> U(-1., 1.);
    const std::size_t                      points = 3;
    std::vector<std::vector<double>>       G(n, std::vector<double>(n)), A(n, std::vector<double>(n, 0.));
    for (auto &row : G)
      for (double &g : row)
        g = U(rng);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
        {
          for (std::size_t k = 0; k < n; ++k)
            A[i][j] += G[i][k] * G[j][k];
          A[i][j] += i == j ? 0.5 : 0.;
        }
    std::vector<std::vector<double>> H(points * block_size, std::vector<double>(n));
    for (auto &row : H)
      for (double &h : row)
        h = U(rng);
    ConeProblemData data;
    data.block_size = block_size;
    data.A          = dense_to_csr(A);
    data.H          = dense_to_csr(H);
    for (std::size_t i = 0; i < n; ++i)
      data.l.push_back(U(rng));
    data.k.assign(points * block_size, 0.);
    data.mu = {0.3, 0.5, 0.8};
    data.Bi = {0., 0., 0.};
    return data;
  }
  /// Expects Corollary 1's complementarity at every point, written out here rather than through
  /// the f_AC / f_FB the solvers stop on: lambda in K_mu (|lambda_T| <= mu lambda_N), gamma_hat =
  /// gamma + mu |gamma_T| e_N in its dual K_{1/mu} (mu |gamma_T| <= gamma_hat_N), and lambda .
  /// gamma_hat = 0, each to `tolerance`. (Bi = 0 and gamma_scale 1, as in these problems.)
  /// Returns how many points are in each of the three cases: lambda = 0 (separating), gamma_hat =
  /// 0 (rigid), both on the boundaries (sliding).
  std::array<int, 3>
  expect_complementarity(const ConeProblemData &data, const std::vector<double> &lambda,
                         const std::vector<double> &gamma, const double tolerance)
  {
    std::array<int, 3> cases{{0, 0, 0}};
    for (std::size_t i = 0; i < data.mu.size(); ++i)
      {
        const double *l = &lambda[3 * i], *g = &gamma[3 * i], mu = data.mu[i];
        const double  lT = std::hypot(l[1], l[2]), gT = std::hypot(g[1], g[2]);
        const double  hat_N = g[0] + mu * gT;
        EXPECT_LE(lT, mu * l[0] + tolerance) << "point " << i << ": lambda outside K_mu";
        EXPECT_LE(mu * gT, hat_N + tolerance) << "point " << i << ": gamma_hat outside K_1/mu";
        EXPECT_NEAR(l[0] * hat_N + l[1] * g[1] + l[2] * g[2], 0., tolerance)
            << "point " << i << ": lambda . gamma_hat";
        ++cases[std::hypot(l[0], lT) <= tolerance ? 0
                                                  : (std::hypot(hat_N, gT) <= tolerance ? 1 : 2)];
      }
    return cases;
  }

  /// DP(mu, Bi) with Bi > 0 at every point, written out by hand (not through the library's
  /// residuals): lambda in the truncated cone K_{mu,Bi} = {lambda_N >= 0, |lambda_T| <= Bi + mu
  /// lambda_N} (16), and gamma_hat = gamma + mu |gamma_T| e_N in minus its normal cone at lambda.
  /// Inside K: gamma = 0. On its side (|lambda_T| = Bi + mu lambda_N): gamma_T = -|gamma_T|
  /// lambda_T / |lambda_T|, else gamma_T = 0. Above its base (lambda_N > 0): gamma_N = 0, else
  /// gamma_N >= 0. `n` is the block size (2D: 3, 3D: 6).
  void
  expect_truncated_cone_law(const ConeProblemData &data, const std::size_t n,
                            const std::vector<double> &lambda, const std::vector<double> &gamma,
                            const double tolerance)
  {
    for (std::size_t i = 0; i < data.mu.size(); ++i)
      {
        ASSERT_GT(data.Bi[i], 0.) << "point " << i;
        const double *l = &lambda[n * i], *g = &gamma[n * i];
        double        lT = 0.;
        for (std::size_t c = 1; c < n; ++c)
          lT += l[c] * l[c];
        lT                  = std::sqrt(lT);
        const double radius = data.Bi[i] + data.mu[i] * l[0];
        EXPECT_GE(l[0], -tolerance) << "point " << i << ": lambda_N < 0";
        EXPECT_LE(lT, radius + tolerance) << "point " << i << ": lambda outside K_{mu,Bi}";
        const bool on_side = lT >= radius - tolerance;
        double     gT      = 0.;
        for (std::size_t c = 1; c < n; ++c)
          gT += g[c] * g[c];
        gT = std::sqrt(gT);
        for (std::size_t c = 1; c < n; ++c)
          EXPECT_NEAR(g[c], on_side ? -gT * l[c] / lT : 0., tolerance)
              << "point " << i << ", component " << c
              << (on_side ? ": side" : ": inside the radius");
        if (l[0] > tolerance)
          EXPECT_NEAR(g[0], 0., tolerance) << "point " << i << ": above the base, gamma_N = 0";
        else
          EXPECT_GE(g[0], -tolerance) << "point " << i << ": at the base, gamma_N >= 0";
      }
  }

  /// u = A^{-1}(H^T lambda + l) (35a), computed here by a fresh factorisation of A.
  std::vector<double>
  velocity_of_stress(const ConeProblemData &data, const std::vector<double> &lambda)
  {
    std::vector<double> rhs, u;
    data.H.Tvmult(rhs, lambda);
    for (std::size_t i = 0; i < rhs.size(); ++i)
      rhs[i] += data.l[i];
    CholmodSolver(data.A).solve(u, rhs);
    return u;
  }

  /// Expects the returned u to be A^{-1}(H^T lambda + l) (35a) to `tolerance`; returns the strain
  /// rate gamma = H u (k = 0) recomputed from it, for the rheology checks.
  std::vector<double>
  expect_velocity_of_stress(const ConeProblemData &data, const ConeSolution &solution,
                            const double tolerance)
  {
    std::vector<double> gamma;
    data.H.vmult(gamma, solution.u);
    const std::vector<double> u = velocity_of_stress(data, solution.lambda);
    for (std::size_t i = 0; i < u.size(); ++i)
      EXPECT_NEAR(u[i], solution.u[i], tolerance);
    return gamma;
  }

  /// One constraint point, W = I: gamma = lambda + w. The disjunctive form (4)/(13) gives the
  /// solution by hand: take-off, sticking or sliding.
  std::array<double, 3>
  single_point_lambda(const std::array<double, 3> &w, double mu, double Bi)
  {
    const double wT = std::hypot(w[1], w[2]);
    if (Bi == 0. && w[0] >= 0.)
      return {{0., 0., 0.}}; // take-off: gamma = w, gamma_hat = (w_N + mu |w_T|; w_T) in K_{1/mu}
    if (Bi > 0. && mu == 0.)
      {
        const double s = wT <= Bi ? 1. : Bi / wT;
        return {{std::max(0., -w[0]), -s * w[1], -s * w[2]}};
      }
    if (mu * (-w[0]) >= wT)
      return {{-w[0], -w[1], -w[2]}}; // sticking: gamma = 0
    const double lN = -w[0];        // sliding: gamma_N = 0, lambda_T = -mu lambda_N w_T / |w_T|
    return {{lN, -mu * lN * w[1] / wT, -mu * lN * w[2] / wT}};
  }
} // namespace

class ConeSolverAllInner : public ::testing::TestWithParam<InnerSolver>
{
};

TEST_P(ConeSolverAllInner, SinglePointMatchesDisjunctiveSolution)
{
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> U(-1., 1.);
  int                                    cases[3] = {0, 0, 0};
  for (int trial = 0; trial < 200; ++trial)
    {
      const double          mu = trial % 4 == 0 ? 0. : 0.2 + 0.8 * std::abs(U(rng));
      const double          Bi = (trial % 4 == 0) ? 0.3 : 0.;
      std::array<double, 3> w    = {{U(rng), U(rng), U(rng)}};
      const ConeProblemData data = single_point_problem({{w[0], w[1], w[2]}}, mu, Bi);
      ConeSolverOptions     options;
      options.inner_solver = GetParam();
      options.residual     = ResidualKind::alart_curnier;
      options.tolerance    = 1e-10;
      ConeSolution       solution;
      std::ostringstream log;
      options.log      = &log;
      const auto stats = solve_cone_problem(data, options, solution);
      ASSERT_TRUE(stats.converged) << "trial " << trial << " mu " << mu << " Bi " << Bi << "\n"
                                   << log.str();
      const auto expected = single_point_lambda(w, mu, Bi);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(solution.lambda[c], expected[c], 1e-8) << "trial " << trial << " mu " << mu;
      const double wT = std::hypot(w[1], w[2]);
      ++cases[Bi > 0. ? 0 : (w[0] >= 0. ? 0 : (mu * -w[0] >= wT ? 1 : 2))];
    }
  EXPECT_GT(cases[1], 0);
  EXPECT_GT(cases[2], 0);
}

TEST_P(ConeSolverAllInner, CoupledProblemSatisfiesRheologyAndAgreesAcrossSolvers)
{
  // A random SPD A (10 dofs), H coupling 3 points: solve, then check f_AC = 0 at every point with
  // gamma recomputed from u, and u = A^{-1}(H^T lambda + l).
  const ConeProblemData data = coupled_random_problem();
  const std::size_t     n    = data.A.n_rows;

  ConeSolverOptions options;
  options.inner_solver = GetParam();
  options.tolerance    = 1e-9;
  ConeSolution solution;
  std::ostringstream log;
  options.log        = &log;
  const auto   stats = solve_cone_problem(data, options, solution);
  ASSERT_TRUE(stats.converged) << log.str();

  const std::vector<double> gamma = expect_velocity_of_stress(data, solution, 1e-10);
  EXPECT_LE(cone_residual(data, ResidualKind::alart_curnier, solution.lambda, gamma), 1e-7);
  EXPECT_LE(cone_residual(data, ResidualKind::fischer_burmeister, solution.lambda, gamma), 1e-7);
  const auto cases = expect_complementarity(data, solution.lambda, gamma, 1e-7);
  EXPECT_GT(cases[0], 0) << "a separating point is exercised";
  EXPECT_GT(cases[2], 0) << "a sliding point is exercised";
  RecordProperty("separating_rigid_sliding", std::to_string(cases[0]) + " " +
                                                 std::to_string(cases[1]) + " " +
                                                 std::to_string(cases[2]));

  // Every inner solver finds the same u (at fixed s it is unique, Section 4.4.4): compared with
  // another one's.
  ConeSolverOptions reference_options = options;
  reference_options.inner_solver      = GetParam() == InnerSolver::projected_gradient
                                            ? InnerSolver::apgd
                                            : InnerSolver::projected_gradient;
  ConeSolution reference;
  ASSERT_TRUE(solve_cone_problem(data, reference_options, reference).converged);
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_NEAR(solution.u[i], reference.u[i], 1e-6);
}

namespace
{
  /// Solves coupled_random_problem() and the same problem with A -> c A, gamma_scale = c (c =
  /// 1e12: the dp model's A carries 1/Re, so this is Re = 1e-12). That leaves lambda as it is and
  /// divides u and gamma = H u by c (k = 0): W = H A^{-1} H^T -> W / c, and DP(mu, 0) is
  /// homogeneous in gamma; with gamma_scale = c the residual is the unscaled one. Expects both
  /// to converge, to the same lambda and c u within `relative` (of lambda's size, and of 1 for
  /// u), and returns their stats (unscaled, scaled).
  std::pair<ConeSolverStats, ConeSolverStats>
  expect_scaled_problem_solved(ConeSolverOptions options, const double relative)
  {
    const ConeProblemData data   = coupled_random_problem();
    const double          c      = 1e12;
    ConeProblemData       scaled = data;
    for (double &a : scaled.A.value)
      a *= c;
    scaled.gamma_scale.assign(data.n_points(), c);

    ConeSolution       solution, scaled_solution;
    std::ostringstream log, scaled_log;
    options.log             = &log;
    const auto stats        = solve_cone_problem(data, options, solution);
    options.log             = &scaled_log;
    const auto scaled_stats = solve_cone_problem(scaled, options, scaled_solution);
    EXPECT_TRUE(stats.converged) << log.str();
    EXPECT_TRUE(scaled_stats.converged) << scaled_log.str();
    const double lambda_max = detail::norm_inf(solution.lambda);
    for (std::size_t j = 0; j < solution.lambda.size(); ++j)
      EXPECT_NEAR(scaled_solution.lambda[j], solution.lambda[j], relative * lambda_max) << j;
    for (std::size_t i = 0; i < solution.u.size(); ++i)
      EXPECT_NEAR(c * scaled_solution.u[i], solution.u[i], relative) << i;
    return {stats, scaled_stats};
  }
} // namespace

TEST_P(ConeSolverAllInner, ScalingAIsSolvedInTheSameIterations)
{
  // Each inner solver must take about the same iterations on the scaled problem: its step
  // bounds must scale with 1/||W||. SPG's former absolute cap on the Barzilai-Borwein step
  // (1e10) fell below 1/||W|| here (47 inner iterations unscaled, 2905 scaled).
  ConeSolverOptions options;
  options.inner_solver             = GetParam();
  options.tolerance                = 1e-9;
  const auto [stats, scaled_stats] = expect_scaled_problem_solved(options, 1e-6);
  EXPECT_LE(scaled_stats.inner_iterations, 2 * stats.inner_iterations + 10)
      << "unscaled: " << stats.inner_iterations << ", scaled: " << scaled_stats.inner_iterations;
  RecordProperty("inner_iterations_unscaled_scaled",
                 std::to_string(stats.inner_iterations) + " " +
                     std::to_string(scaled_stats.inner_iterations));
}

namespace
{
  /// One constraint point in s(d) = n components with A = H = I (so W = I, gamma = lambda + w,
  /// w = l) and Bi = 0: the disjunctive solution of (4)/(13), take-off, sticking or sliding, in any
  /// block size; returns which case (0, 1, 2).
  template <std::size_t n>
  int
  single_point_solution(const std::array<double, n> &w, const double mu,
                        std::array<double, n> &lambda)
  {
    double wT = 0.;
    for (std::size_t j = 1; j < n; ++j)
      wT += w[j] * w[j];
    wT = std::sqrt(wT);
    lambda.fill(0.);
    if (w[0] >= 0.)
      return 0;
    lambda[0] = -w[0];
    for (std::size_t j = 1; j < n; ++j)
      lambda[j] = mu * -w[0] >= wT ? -w[j] : -mu * lambda[0] * w[j] / wT;
    return mu * -w[0] >= wT ? 1 : 2;
  }

  template <std::size_t n>
  void
  check_interior_point_single_points(const unsigned int seed, const double split_form)
  {
    std::mt19937                           rng(seed);
    std::uniform_real_distribution<double> U(-1., 1.);
    int                                    cases[3] = {0, 0, 0};
    for (int trial = 0; trial < 100; ++trial)
      {
        const double          mu = 0.2 + 0.8 * std::abs(U(rng));
        std::array<double, n> w;
        for (std::size_t j = 0; j < n; ++j) // every other trial a small w_T, so that sticking
          w[j] =
              (j > 0 && trial % 2 ? 0.2 : 1.) * U(rng); // occurs with 5 tangential components too
        const ConeProblemData data = single_point_problem({w.begin(), w.end()}, mu, 0.);
        ConeSolverOptions     options;
        options.method                                = ConeMethod::interior_point;
        options.interior_point.split_form             = split_form;
        options.interior_point.whole_form_after_stall  = 0.; // the form under test alone
        options.interior_point.fixed_point_after_stall = 0.;
        options.tolerance                             = 1e-9;
        ConeSolution       solution;
        std::ostringstream log;
        options.log      = &log;
        const auto stats = solve_cone_problem(data, options, solution);
        ASSERT_TRUE(stats.converged) << "trial " << trial << " mu " << mu << "\n" << log.str();
        std::array<double, n> expected;
        ++cases[single_point_solution(w, mu, expected)];
        for (std::size_t c = 0; c < n; ++c)
          EXPECT_NEAR(solution.lambda[c], expected[c], 1e-7) << "trial " << trial << " mu " << mu;
      }
    for (const int c : cases) // take-off, sticking and sliding are all exercised
      EXPECT_GT(c, 0);
  }
} // namespace

// Each test of the interior point runs on the split form of the law (InteriorPointTunables::
// split_form = 1, cone_split_interior_point.cc) and on the whole one (0, cone_interior_point.cc).
class ConeInteriorPointForms : public ::testing::TestWithParam<double>
{
};

TEST_P(ConeInteriorPointForms, ScalingAIsSolved)
{
  // The interior point on expect_scaled_problem_solved's problem (as at Re = 1e-12) converges to
  // the same lambda and c u, to the solver's tolerance: two solutions each to 1e-6, which differ
  // by up to 2e-5 of lambda's size here. Its iterations are not the same: both forms start from
  // points in the units of gamma (the split form from slacks of 1, the whole form from a
  // least-squares point with W = I), 10 and 16 iterations (split), 12 and 15 (whole) here;
  // docs/solvers.md.
  ConeSolverOptions options;
  options.method                    = ConeMethod::interior_point;
  options.interior_point.split_form = GetParam();
  options.tolerance                 = 1e-6;
  const auto [stats, scaled_stats]  = expect_scaled_problem_solved(options, 1e-4);
  EXPECT_LE(scaled_stats.outer_iterations, 2 * stats.outer_iterations);
}

TEST_P(ConeInteriorPointForms, SinglePointMatchesDisjunctiveSolution2D)
{
  check_interior_point_single_points<3>(7, GetParam());
}

TEST_P(ConeInteriorPointForms, SinglePointMatchesDisjunctiveSolution3D)
{
  check_interior_point_single_points<6>(8, GetParam());
}

TEST_P(ConeInteriorPointForms, CoupledProblemAgreesWithTheFixedPoint)
{
  // The coupled random problem above (10 dofs, 3 points, mu = 0.3, 0.5, 0.8): the interior point
  // on the whole problem and Cadoux's fixed point find the same u, and lambda
  // satisfies the rheology with gamma recomputed from u.
  const ConeProblemData data = coupled_random_problem();
  const std::size_t     n    = data.A.n_rows;

  // Tolerance 1e-7: at a point where lambda and gamma_hat both vanish the residual decreases only
  // like the square root of the duality gap; this problem stops at 1.1e-8 with a gap of 3e-14.
  ConeSolverOptions options;
  options.method                                = ConeMethod::interior_point;
  options.interior_point.split_form             = GetParam();
  options.interior_point.whole_form_after_stall  = 0.; // the form under test alone
  options.interior_point.fixed_point_after_stall = 0.;
  options.tolerance                             = 1e-7;
  std::ostringstream log;
  options.log = &log;
  ConeSolution solution;
  const auto   stats = solve_cone_problem(data, options, solution);
  ASSERT_TRUE(stats.converged) << log.str();

  const std::vector<double> gamma = expect_velocity_of_stress(data, solution, 1e-8);
  EXPECT_LE(cone_residual(data, ResidualKind::alart_curnier, solution.lambda, gamma), 1e-7);
  expect_complementarity(data, solution.lambda, gamma, 1e-6);

  ConeSolverOptions reference_options;
  reference_options.inner_solver = InnerSolver::projected_gradient;
  reference_options.tolerance    = 1e-9;
  ConeSolution reference;
  ASSERT_TRUE(solve_cone_problem(data, reference_options, reference).converged);
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_NEAR(solution.u[i], reference.u[i], 1e-6);
}

TEST(ConeFrozenInteriorPoint, SinglePointIsTheProjectionOfTheShiftedLoad)
{
  // With A = H = I (W = I) and s frozen, the convex step (37) is min 1/2 |lambda|^2 + lambda . (w
  // + s e_N) over K_mu: lambda is the Euclidean projection of -(w + s e_N) onto K_mu, computed
  // here by the rheology's projection, not by the solver.
  std::mt19937                           rng(5);
  std::uniform_real_distribution<double> U(-1., 1.);
  int                                    cases[3] = {0, 0, 0};
  for (int trial = 0; trial < 100; ++trial)
    {
      const double                mu   = 0.2 + 0.8 * std::abs(U(rng));
      const std::array<double, 3> w    = {{U(rng), U(rng), U(rng)}};
      const std::vector<double>   s    = {trial % 3 == 0 ? 0. : std::abs(U(rng))};
      const ConeProblemData       data = single_point_problem({w.begin(), w.end()}, mu, 0.);
      ConeSolverOptions           options;
      options.tolerance = 1e-10;
      ConeSolution solution;
      ASSERT_TRUE(solve_frozen_cone_problem_interior_point(data, s, options, solution).converged)
          << "trial " << trial;
      const std::array<double, 3> y        = {{-(w[0] + s[0]), -w[1], -w[2]}};
      const auto                  expected = granflow::rheology::project_onto_cone(y, mu);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(solution.lambda[c], expected[c], 1e-8) << "trial " << trial;
      const double yT = std::hypot(y[1], y[2]);
      ++cases[mu * yT <= -y[0] ? 0
                               : (yT <= mu * y[0] ? 1 : 2)]; // apex (polar cone), interior, face
    }
  for (const int c : cases)
    EXPECT_GT(c, 0);
}

TEST(ConeFrozenInteriorPoint, TheFixedPointWithInteriorPointStepsAgreesWithTheFirstOrderOne)
{
  // Cadoux's fixed point with each convex step solved by the interior point (4.4.2), on the
  // coupled random problem (3 points, mu = 0.3, 0.5, 0.8) in 2D and 3D: it converges, the
  // rheology holds with gamma recomputed from u, and u is the fixed point's with PG steps. In 3D
  // the interior point's steps stop near 1e-7 (as the interior point alone does there), so the
  // fixed point is asked for 1e-6.
  for (const std::size_t block_size : {3u, 6u})
    {
      const double          tolerance = block_size == 3 ? 1e-8 : 1e-6;
      // About 10 times the largest difference measured (3.9e-9 in 2D, 2.2e-7 in 3D).
      const double          u_bound = block_size == 3 ? 5e-8 : 3e-6;
      const ConeProblemData data = coupled_random_problem(block_size, block_size == 3 ? 10 : 20);
      ConeSolverOptions     options;
      options.inner_solver = InnerSolver::interior_point;
      options.tolerance    = tolerance;
      std::ostringstream log;
      options.log = &log;
      ConeSolution solution;
      const auto   stats = solve_cone_problem(data, options, solution);
      ASSERT_TRUE(stats.converged) << "block size " << block_size << "\n" << log.str();
      EXPECT_NE(log.str().find("Cadoux fixed point (interior point)"), std::string::npos)
          << "the steps are interior-point solves";
      EXPECT_EQ(stats.residual_history.size(), stats.outer_iterations + 1)
          << "the starting iterate, then one residual per step";
      const std::vector<double> gamma = expect_velocity_of_stress(data, solution, 1e-9);
      if (block_size == 3) // written out for 2D blocks
        expect_complementarity(data, solution.lambda, gamma, 1e-7);
      EXPECT_LE(cone_residual(data, ResidualKind::alart_curnier, solution.lambda, gamma),
                10. * tolerance);

      ConeSolverOptions reference_options;
      reference_options.inner_solver = InnerSolver::projected_gradient;
      reference_options.tolerance    = 1e-9;
      ConeSolution reference;
      ASSERT_TRUE(solve_cone_problem(data, reference_options, reference).converged);
      for (std::size_t i = 0; i < data.A.n_rows; ++i)
        EXPECT_NEAR(solution.u[i], reference.u[i], u_bound) << "block size " << block_size;

      // Its scope is the whole-form interior point's: mu > 0 and Bi = 0 at every point.
      ConeProblemData bingham = data;
      bingham.Bi[1]           = 0.2;
      EXPECT_THROW(solve_cone_problem(bingham, options, solution), std::invalid_argument);
    }
}

TEST(ConeInteriorPoint, ReducedAndAugmentedNewtonSystemsGiveTheSameIterates)
{
  // The whole form's Newton step solved through the velocity block with the stress eliminated
  // (its default) or through the augmented matrix: the same directions
  // up to rounding, so the same iterations and, to the tolerance, the same solution. A reduced
  // solve whose backward error cannot be brought within reduced_accuracy hands over to the
  // augmented matrix; with an unreachable accuracy that happens at the first solve, and every
  // iterate is then the augmented path's, bit for bit.
  const ConeProblemData data = coupled_random_problem();
  std::string           hand_over; // the log's hand-over line(s) of the last run
  const auto            run = [&](const double reduced, const double accuracy,
                       const unsigned int refinement_steps = 3,
                       const unsigned int iterations       = 200) {
    std::stringstream log;
    ConeSolverOptions options;
    options.log                             = &log;
    options.method                          = ConeMethod::interior_point;
    options.interior_point.split_form       = 0.;
    options.tolerance                       = 1e-7;
    options.max_outer_iterations            = iterations;
    options.interior_point.reduced_system   = reduced;
    options.interior_point.reduced_accuracy = accuracy;
    options.interior_point.refinement_steps = refinement_steps;
    ConeSolution solution;
    const auto   stats = solve_cone_problem(data, options, solution);
    EXPECT_TRUE(stats.converged || iterations < 200);
    hand_over.clear();
    for (std::string line; std::getline(log, line);)
      if (line.find("augmented matrix") != std::string::npos)
        hand_over += line + "\n";
    return std::make_pair(stats, solution);
  };
  const auto [augmented_stats, augmented] = run(0., 1e-14);
  EXPECT_EQ(hand_over, "");
  // The defaults hand over in the middle of the solve (here in iteration 10's predictor; rounding
  // may move it), so the comparison covers both paths and the switch between them.
  const auto [reduced_stats, reduced] = run(1., 1e-14);
  EXPECT_TRUE(std::regex_match(
      hand_over, std::regex("  iteration ([1-9]|1[0-9]): the Newton systems go to the "
                            "augmented matrix from here on \\(in the (predictor|corrector), the "
                            "reduced solve's backward error was .* after 3 "
                            "refinement steps \\(reduced_accuracy 1e-14\\)\\)\n")))
      << hand_over;
  const auto [handed_stats, handed_over] = run(1., -1.);
  EXPECT_EQ(
      hand_over.rfind("  iteration 0: the Newton systems go to the augmented matrix from here "
                      "on (in the starting point, ",
                      0),
      0u)
      << hand_over;
  EXPECT_EQ(std::count(hand_over.begin(), hand_over.end(), '\n'), 1) << hand_over; // once
  // The elimination alone, unrefined, over the first 5 iterations, while W^2 spans few decades.
  const auto [early_stats, early] = run(0., 1., 3, 5);
  const auto [raw_stats, raw]     = run(1., 1., 0, 5);
  // Rounding differs, and near the end of the path, where the complementarity is 1e-14, it moves
  // the iterates at the level of the residual (5.1e-8 and 7.3e-8 here): u agrees to 1e-7.
  EXPECT_NEAR(reduced_stats.outer_iterations, augmented_stats.outer_iterations, 1);
  for (std::size_t i = 0; i < augmented.u.size(); ++i)
    {
      EXPECT_NEAR(reduced.u[i], augmented.u[i], 1e-7);
      EXPECT_NEAR(raw.u[i], early.u[i], 1e-10);
    }
  EXPECT_EQ(handed_stats.outer_iterations, augmented_stats.outer_iterations);
  EXPECT_EQ(handed_stats.residual, augmented_stats.residual);
  EXPECT_EQ(handed_over.u, augmented.u);
  // one factorisation more: the reduced one of the first solve, before the hand-over
  EXPECT_EQ(handed_stats.operator_applications, augmented_stats.operator_applications + 1);
}

TEST(ConeInteriorPoint, CoupledProblemAgreesWithTheFixedPoint3D)
{
  // The same kind of problem in 3D (blocks of 6, 20 dofs, 3 points): the whole form alone and the
  // default reach 1e-7 and find the u of Cadoux's fixed point; the Alart-Curnier residual of
  // lambda and the gamma recomputed from u is small. In the default the split form ends near
  // 1e-7 either way the factorisation rounds: with Debian's reference BLAS it stalls at 2.15e-7
  // (steps of 1e-4) and the whole form finishes, with OpenBLAS it reaches 9.0e-8 itself. So the
  // hand-over is checked where it happens (the 2D tests above force it).
  const ConeProblemData data = coupled_random_problem(6, 20);
  ConeSolverOptions     reference_options;
  reference_options.inner_solver = InnerSolver::projected_gradient;
  reference_options.tolerance    = 1e-9;
  ConeSolution reference;
  ASSERT_TRUE(solve_cone_problem(data, reference_options, reference).converged);
  for (const double split_form : {0., 1.})
    {
      ConeSolverOptions options;
      options.method                    = ConeMethod::interior_point;
      options.interior_point.split_form = split_form;
      options.tolerance                 = 1e-7;
      std::ostringstream log;
      options.log = &log;
      ConeSolution solution;
      ASSERT_TRUE(solve_cone_problem(data, options, solution).converged) << log.str();
      const bool handed_over = log.str().find("the split form stalled") != std::string::npos;
      if (split_form == 0.)
        EXPECT_FALSE(handed_over) << log.str();
      else if (handed_over) // the whole form's own table follows
        EXPECT_NE(
            log.str().find("  interior point (Mehrotra", log.str().find("the split form stalled")),
            std::string::npos)
            << log.str();
      const std::vector<double> gamma = expect_velocity_of_stress(data, solution, 1e-8);
      EXPECT_LE(cone_residual(data, ResidualKind::alart_curnier, solution.lambda, gamma), 1e-7);
      for (std::size_t i = 0; i < data.A.n_rows; ++i)
        EXPECT_NEAR(solution.u[i], reference.u[i], 1e-6) << "split_form " << split_form;
    }
}

TEST_P(ConeInteriorPointForms, ItsStallRulesAreTheOptionsTunables)
{
  // The coupled problem converges in about 20 iterations with the default tunables; each stall
  // rule, tightened through ConeSolverOptions::interior_point, ends it earlier and is named.
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.method                                = ConeMethod::interior_point;
  options.interior_point.split_form             = GetParam();
  options.interior_point.whole_form_after_stall  = 0.; // each form alone
  options.interior_point.fixed_point_after_stall = 0.;
  options.tolerance                             = 1e-7;
  ConeSolution solution;
  ASSERT_TRUE(solve_cone_problem(data, options, solution).converged);

  ConeSolverOptions short_steps          = options;
  short_steps.interior_point.short_step  = 2.; // every step (at most 1) is short
  short_steps.interior_point.short_steps = 3;
  auto stats                             = solve_cone_problem(data, short_steps, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, 3u);
  EXPECT_EQ(stats.stall_reason, "3 successive steps were shorter than 2 (the iterates left the "
                                "central path)");

  ConeSolverOptions stagnation                    = options;
  stagnation.interior_point.stagnation_iterations = 2;
  stagnation.interior_point.stagnation_ratio      = 0.; // no residual counts as a gain
  stats                                           = solve_cone_problem(data, stagnation, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, 2u);
  EXPECT_EQ(stats.stall_reason, "2 iterations gained less than 100 % on the least residual");

  // The rule the chain sets for its whole form: no residual below beat_residual within
  // beat_within iterations. None is below 0; every one is below 1e300, which changes nothing.
  ConeSolverOptions unbeaten            = options;
  unbeaten.interior_point.beat_within   = 3;
  unbeaten.interior_point.beat_residual = 0.;
  stats                                 = solve_cone_problem(data, unbeaten, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, 3u);
  EXPECT_EQ(
      stats.stall_reason.rfind("3 iterations did not bring the residual below 0 (its least: ", 0),
      0u)
      << stats.stall_reason;
  unbeaten.interior_point.beat_residual = 1e300;
  EXPECT_TRUE(solve_cone_problem(data, unbeaten, solution).converged);
}

TEST(ConeInteriorPoint, AStalledSplitSolveIsFollowedByTheWholeForm)
{
  // The default: the split form, and where it stalls the whole form from its own start; the
  // iterate of least residual is returned, with the two solves' statistics together.
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.method    = ConeMethod::interior_point;
  options.tolerance = 1e-7;
  std::ostringstream log;
  options.log = &log;
  ConeSolution solution;
  auto         stats = solve_cone_problem(data, options, solution);
  ASSERT_TRUE(stats.converged) << log.str();
  EXPECT_EQ(log.str().find("the whole form"), std::string::npos); // the split form converged

  // Both forms made to stall after 2 iterations without a gain; each alone, then the two (the
  // fixed point that would follow them is tested below).
  ConeSolverOptions stalling                    = options;
  stalling.interior_point.stagnation_iterations = 2;
  stalling.interior_point.stagnation_ratio      = 0.;
  stalling.interior_point.fixed_point_after_stall = 0.;
  ConeSolverOptions split_only = stalling, whole_only = stalling;
  split_only.interior_point.whole_form_after_stall = 0.;
  whole_only.interior_point.split_form             = 0.;
  ConeSolution split_solution, whole_solution;
  const auto   split = solve_cone_problem(data, split_only, split_solution);
  const auto   whole = solve_cone_problem(data, whole_only, whole_solution);
  ASSERT_TRUE(split.stalled && whole.stalled);
  log.str("");
  // Progress is numbered on across the two solves, each number once: the iterate after each
  // step but the last, which stalled and is not evaluated, and the starting point.
  std::vector<unsigned int> reported;
  stalling.progress = [&](const unsigned int k, double) { reported.push_back(k); };
  stats             = solve_cone_problem(data, stalling, solution);
  std::vector<unsigned int> expected(stats.outer_iterations);
  std::iota(expected.begin(), expected.end(), 0u);
  EXPECT_EQ(reported, expected);
  EXPECT_TRUE(stats.stalled);
  EXPECT_FALSE(stats.converged);
  EXPECT_EQ(stats.outer_iterations, split.outer_iterations + whole.outer_iterations);
  EXPECT_EQ(stats.operator_applications, split.operator_applications + whole.operator_applications);
  EXPECT_EQ(stats.residual, std::min(split.residual, whole.residual));
  EXPECT_EQ(stats.residual, cone_residual(data, options.residual, solution.lambda, solution.gamma));
  EXPECT_EQ(solution.u, split.residual <= whole.residual ? split_solution.u : whole_solution.u);
  EXPECT_EQ(stats.stall_reason, "split form: 2 iterations gained less than 100 % on the least "
                                "residual; then whole form: 2 iterations gained less than 100 % "
                                "on the least residual");
  ASSERT_EQ(stats.residual_history.size(),
            split.residual_history.size() + whole.residual_history.size());
  EXPECT_TRUE(std::is_sorted(stats.time_history.begin(), stats.time_history.end()));
  EXPECT_NE(log.str().find("  the split form stalled at "), std::string::npos) << log.str();
  EXPECT_NE(
      log.str().find(") after " + std::to_string(split.outer_iterations) + " iterations and "),
      std::string::npos)
      << log.str();

  // The iteration limit covers both solves: with room for one more iteration after the split
  // form's, the whole form takes one.
  ConeSolverOptions limited    = stalling;
  limited.max_outer_iterations = split.outer_iterations + 1;
  stats                        = solve_cone_problem(data, limited, solution);
  EXPECT_EQ(stats.outer_iterations, split.outer_iterations + 1);
  limited.max_outer_iterations = split.outer_iterations;
  stats                        = solve_cone_problem(data, limited, solution);
  EXPECT_EQ(stats.outer_iterations, split.outer_iterations);
  EXPECT_EQ(stats.stall_reason, split.stall_reason); // the split form's alone

  // Without the whole form after a stall, the split form's own statistics.
  stats = solve_cone_problem(data, split_only, solution);
  EXPECT_EQ(stats.outer_iterations, split.outer_iterations);
  EXPECT_EQ(stats.residual, split.residual);

  // A split form that stalls at its floor (tolerance 1e-13, 5 iterations without a 10 % gain),
  // and a whole form with whole_form_patience = 0.5: half the split form's iterations are too few
  // for it to go below the split form's least residual, and it stalls then.
  ConeSolverOptions impatient                           = options;
  impatient.tolerance                                   = 1e-13;
  impatient.interior_point.stagnation_iterations        = 5;
  impatient.interior_point.fixed_point_after_stall      = 0.;
  impatient.interior_point.whole_form_patience          = 0.5;
  ConeSolverOptions impatient_split                     = impatient;
  impatient_split.interior_point.whole_form_after_stall = 0.;
  const auto floor = solve_cone_problem(data, impatient_split, split_solution);
  ASSERT_TRUE(floor.stalled);
  const unsigned int patience = (floor.outer_iterations + 1) / 2;
  stats                       = solve_cone_problem(data, impatient, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, floor.outer_iterations + patience);
  EXPECT_EQ(stats.residual, floor.residual);
  EXPECT_NE(stats.stall_reason.find("then whole form: " + std::to_string(patience) +
                                    " iterations did not bring the residual below " +
                                    granflow::solvers::detail::as_written(floor.residual)),
            std::string::npos)
      << stats.stall_reason;
}

TEST(ConeInteriorPoint, AStalledInteriorPointIsFollowedByTheFixedPointFromItsBestIterate)
{
  // The chain's third stage: where the split and the whole form have stalled, Cadoux's fixed
  // point with interior-point steps, started from the stress of the better of their iterates,
  // with the velocity of the momentum balance (35a). Both forms are made to stall after 2
  // iterations without a gain. The steps' own solves then stall so too, and the fixed point
  // gains nothing here: what is checked is the chain's bookkeeping, against the two forms'
  // chain alone (that it gains where the forms stall is measured on the silo: docs/solvers.md).
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.method                               = ConeMethod::interior_point;
  options.tolerance                            = 1e-7;
  options.interior_point.stagnation_iterations   = 2;
  options.interior_point.stagnation_ratio        = 0.;
  ASSERT_EQ(options.interior_point.fixed_point_after_stall, 1.); // (the default)
  ConeSolverOptions two_forms                      = options;
  two_forms.interior_point.fixed_point_after_stall = 0.;
  ConeSolution forms_solution;
  const auto   forms = solve_cone_problem(data, two_forms, forms_solution);
  ASSERT_TRUE(forms.stalled);

  std::ostringstream log;
  options.log = &log;
  std::vector<unsigned int> reported;
  options.progress = [&](const unsigned int k, double) { reported.push_back(k); };
  ConeSolution solution;
  const auto   stats = solve_cone_problem(data, options, solution);
  EXPECT_NE(log.str().find("s in all: Cadoux's fixed point with interior-point steps, from the "
                           "best iterate"),
            std::string::npos)
      << log.str();
  EXPECT_NE(log.str().find("Cadoux fixed point (interior point)"), std::string::npos);
  // The fixed point's first record is its start: the forms' best stress, its velocity by (35a).
  ConeSolution start = forms_solution;
  start.u            = velocity_of_stress(data, start.lambda);
  data.H.vmult(start.gamma, start.u); // k = 0
  ASSERT_GT(stats.residual_history.size(), forms.residual_history.size());
  EXPECT_DOUBLE_EQ(stats.residual_history[forms.residual_history.size()],
                   cone_residual(data, options.residual, start.lambda, start.gamma));
  const unsigned int steps = stats.outer_iterations - forms.outer_iterations;
  EXPECT_GE(steps, 1u);
  EXPECT_EQ(stats.fixed_point_steps, steps);
  EXPECT_EQ(forms.fixed_point_steps, 0u);
  EXPECT_EQ(stats.residual_history.size(), forms.residual_history.size() + steps + 1);
  EXPECT_GT(stats.inner_iterations, 0u); // the steps' interior-point iterations
  EXPECT_TRUE(std::is_sorted(stats.time_history.begin(), stats.time_history.end()));
  EXPECT_TRUE(stats.stalled);
  EXPECT_EQ(stats.stall_reason.find(forms.stall_reason + "; then fixed point: the least residual "
                                                          "of its last "),
            0u)
      << stats.stall_reason;
  // The least residual of all stages, and its iterate.
  const double least =
      *std::min_element(stats.residual_history.begin(), stats.residual_history.end());
  EXPECT_EQ(stats.residual, least);
  EXPECT_LE(stats.residual, forms.residual);
  EXPECT_EQ(stats.residual, cone_residual(data, options.residual, solution.lambda, solution.gamma));
  // Progress numbered on, each number once.
  std::vector<unsigned int> expected(stats.outer_iterations);
  std::iota(expected.begin(), expected.end(), 0u);
  EXPECT_EQ(reported, expected);

  // The iteration limit covers it: with no iteration left after the forms, it does not start;
  // with one left, it takes one step.
  ConeSolverOptions limited    = options;
  limited.log                  = nullptr;
  limited.progress             = nullptr;
  limited.max_outer_iterations = forms.outer_iterations;
  const auto capped            = solve_cone_problem(data, limited, solution);
  EXPECT_EQ(capped.outer_iterations, forms.outer_iterations);
  EXPECT_EQ(capped.fixed_point_steps, 0u);
  EXPECT_EQ(capped.residual, forms.residual);
  limited.max_outer_iterations = forms.outer_iterations + 1;
  EXPECT_EQ(solve_cone_problem(data, limited, solution).outer_iterations,
            forms.outer_iterations + 1);
}

TEST(ConeFrozenInteriorPoint, TheFixedPointWithInteriorPointStepsStartsFromTheGivenStress)
{
  // As the first-order fixed point, the one with interior-point steps starts from the stress in
  // the solution it is given (of the problem's size): from its own converged iterate it takes
  // no step; from a perturbed one it converges again to the same velocity.
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.inner_solver = InnerSolver::interior_point;
  options.tolerance    = 1e-8;
  ConeSolution solution;
  const auto   cold = solve_cone_problem(data, options, solution);
  ASSERT_TRUE(cold.converged);
  ASSERT_GT(cold.outer_iterations, 0u);
  ConeSolution warm = solution;
  auto         stats = solve_cone_problem(data, options, warm);
  EXPECT_TRUE(stats.converged);
  EXPECT_EQ(stats.outer_iterations, 0u);
  EXPECT_DOUBLE_EQ(stats.residual, cold.residual);
  for (double &l : warm.lambda)
    l *= 1.1;
  stats = solve_cone_problem(data, options, warm);
  EXPECT_TRUE(stats.converged);
  EXPECT_GT(stats.residual_history.front(), options.tolerance); // it did start from there
  for (std::size_t i = 0; i < data.A.n_rows; ++i)
    EXPECT_NEAR(warm.u[i], solution.u[i], 5e-8);
}

TEST(ConeFrozenInteriorPoint, AWarmStartedStepReachesTheColdStepsSolutionInFewerIterations)
{
  // A frozen step (37) started from the solution of the step at a nearby s
  // (InteriorPointTunables::warm_start_shift > 0, the default) ends at
  // the solution of the cold start: the step is convex, with a unique velocity. It takes fewer
  // iterations, and with warm_start_shift = 0 the given solution is ignored.
  for (const std::size_t block_size : {3u, 6u})
    {
      const ConeProblemData data = coupled_random_problem(block_size, block_size == 3 ? 10 : 20);
      ConeSolverOptions     options;
      options.tolerance                       = 1e-6; // (these steps stall near 1e-7)
      options.interior_point.warm_start_shift = 0.;   // cold
      const std::vector<double> s0 = {0.1, 0.2, 0.3}, s1 = {0.1001, 0.2002, 0.3003};
      ConeSolution              previous, cold;
      std::ostringstream        log;
      options.log = &log;
      ASSERT_TRUE(solve_frozen_cone_problem_interior_point(data, s0, options, previous).converged)
          << log.str();
      log.str("");
      const auto cold_stats = solve_frozen_cone_problem_interior_point(data, s1, options, cold);
      ASSERT_TRUE(cold_stats.converged) << "block size " << block_size << "\n" << log.str();

      ConeSolverOptions warm_options               = options;
      warm_options.interior_point.warm_start_shift = 10.;
      ConeSolution warm                            = previous;
      const auto   warm_stats =
          solve_frozen_cone_problem_interior_point(data, s1, warm_options, warm);
      EXPECT_TRUE(warm_stats.converged) << "block size " << block_size;
      EXPECT_LT(warm_stats.outer_iterations, cold_stats.outer_iterations)
          << "block size " << block_size;
      for (std::size_t i = 0; i < data.A.n_rows; ++i)
        EXPECT_NEAR(warm.u[i], cold.u[i], 1e3 * options.tolerance) << "block size " << block_size;

      ConeSolution ignored   = previous;
      const auto plain_stats = solve_frozen_cone_problem_interior_point(data, s1, options, ignored);
      EXPECT_EQ(plain_stats.outer_iterations, cold_stats.outer_iterations);
      EXPECT_EQ(ignored.u, cold.u);
    }
}

namespace
{
  /// The split form's linearised system, written out as a dense matrix over
  /// z = (du, da, dlambda, dx) with its right-hand side (rows: momentum balance, slack of gamma_N,
  /// slacks of gamma_T, the two complementarities), solved by Gaussian elimination.
  template <std::size_t n>
  std::vector<double>
  split_direction_by_direct_solve(const ConeProblemData &data, const detail::SplitIterate &it,
                                  const std::vector<double> &rc1, const std::vector<double> &rc2)
  {
    using S               = detail::Soc<n>;
    const std::size_t n_u = data.A.n_rows, n_p = data.n_points(), m = n_p * n;
    const std::size_t da0 = n_u, dl0 = n_u + n_p, dx0 = n_u + n_p + m, size = n_u + n_p + 2 * m;
    const auto        dense = [](const CsrMatrix &C) {
      std::vector<std::vector<double>> D(C.n_rows, std::vector<double>(C.n_cols, 0.));
      for (std::size_t r = 0; r < C.n_rows; ++r)
        for (int k = C.row_start[r]; k < C.row_start[r + 1]; ++k)
          D[r][C.column[k]] += C.value[k];
      return D;
    };
    const auto          A = dense(data.A), H = dense(data.H);
    std::vector<double> gamma, Htl;
    data.H.vmult(gamma, it.u);
    data.H.Tvmult(Htl, it.lambda);
    std::vector<std::vector<double>> K(size, std::vector<double>(size + 1, 0.));
    std::size_t                      row = 0;
    for (std::size_t r = 0; r < n_u; ++r, ++row) // A du - H^T dlambda = -(A u - H^T lambda - l)
      {
        double Au = 0.;
        for (std::size_t c = 0; c < n_u; ++c)
          {
            K[row][c] = A[r][c];
            Au += A[r][c] * it.u[c];
          }
        for (std::size_t q = 0; q < m; ++q)
          K[row][dl0 + q] = -H[q][r];
        K[row][size] = -(Au - Htl[r] - data.l[r]);
      }
    for (std::size_t i = 0; i < n_p; ++i)
      for (std::size_t p = 0; p < n; ++p, ++row) // da - dgamma_N = -r_N, dx_T - dgamma_T = -r_T
        {
          for (std::size_t c = 0; c < n_u; ++c)
            K[row][c] = -H[i * n + p][c];
          const double slack                         = p == 0 ? it.a[i] : it.x[i * n + p];
          K[row][p == 0 ? da0 + i : dx0 + i * n + p] = 1.;
          K[row][size] = -(slack - gamma[i * n + p] - data.k[i * n + p]);
        }
    for (std::size_t i = 0; i < n_p; ++i, ++row) // lambda_N da + a dlambda_N = rc1
      {
        K[row][da0 + i]     = it.lambda[i * n];
        K[row][dl0 + i * n] = it.a[i];
        K[row][size]        = rc1[i];
      }
    for (std::size_t i = 0; i < n_p;
         ++i) // v o (W dx + W^-1 dy) = rc2, dy = (mu dlambda_N, dlambda_T)
      {
        typename S::Block x, y;
        for (std::size_t p = 0; p < n; ++p)
          {
            x[p] = it.x[i * n + p];
            y[p] = it.lambda[i * n + p] * (p == 0 ? data.mu[i] : 1.);
          }
        typename S::Matrix W, W_inv;
        S::nesterov_todd(x, y, W, W_inv);
        const auto v = S::apply(W, x);
        for (std::size_t p = 0; p < n; ++p) // the scaling: W x = W^-1 y, W W^-1 = I
          {
            EXPECT_NEAR(v[p], S::apply(W_inv, y)[p], 1e-12);
            for (std::size_t q = 0; q < n; ++q)
              EXPECT_NEAR(S::multiply(W, W_inv)[p][q], p == q ? 1. : 0., 1e-12);
          }
        for (std::size_t p = 0; p < n; ++p, ++row) // row p of the arrow matrix of v
          {
            for (std::size_t q = 0; q < n; ++q)
              {
                const double arrow = p == 0 ? v[q] : (q == 0 ? v[p] : (p == q ? v[0] : 0.));
                for (std::size_t r = 0; r < n; ++r)
                  {
                    K[row][dx0 + i * n + r] += arrow * W[q][r];
                    K[row][dl0 + i * n + r] += arrow * W_inv[q][r] * (r == 0 ? data.mu[i] : 1.);
                  }
              }
            K[row][size] = rc2[i * n + p];
          }
      }
    EXPECT_EQ(row, size);
    std::vector<double> z;
    EXPECT_TRUE(solve_augmented(K, z));
    return z;
  }
} // namespace

TEST(ConeSplitInteriorPoint, DirectionSolvesTheWholeLinearisedSystem)
{
  // The split form eliminates the slacks and the stress point by point and solves for the
  // velocity alone; its direction must be the solution of the whole linearised system, solved
  // here directly, at a random interior iterate off the central path, in 2D and 3D.
  for (const std::size_t block_size : {std::size_t{3}, std::size_t{6}})
    {
      ConeProblemData                        data = coupled_random_problem(block_size, 20);
      const std::size_t                      n = block_size, n_p = data.n_points(), m = n_p * n;
      std::mt19937                           rng(7);
      std::uniform_real_distribution<double> U(-1., 1.), P(0.2, 1.);
      for (double &k : data.k) // gamma = H u + k with k != 0 (boundary velocities)
        k = U(rng);
      detail::SplitIterate                   it;
      for (std::size_t k = 0; k < data.A.n_rows; ++k)
        it.u.push_back(U(rng));
      std::vector<double> rc1, rc2;
      for (std::size_t i = 0; i < n_p; ++i)
        {
          it.a.push_back(P(rng));
          rc1.push_back(U(rng));
          // lambda in K_mu and x in K_1, both interior: their tangential parts at a random
          // fraction of the radius
          std::vector<double> lT(n - 1), xT(n - 1);
          double              nl = 0., nx = 0.;
          for (std::size_t p = 0; p + 1 < n; ++p)
            {
              lT[p] = U(rng), xT[p] = U(rng);
              nl += lT[p] * lT[p], nx += xT[p] * xT[p];
            }
          const double lN = P(rng), t = P(rng), fl = 0.9 * P(rng), fx = 0.9 * P(rng);
          it.lambda.push_back(lN);
          it.x.push_back(t);
          for (std::size_t p = 0; p + 1 < n; ++p)
            {
              it.lambda.push_back(fl * data.mu[i] * lN * lT[p] / std::sqrt(nl));
              it.x.push_back(fx * t * xT[p] / std::sqrt(nx));
            }
          for (std::size_t p = 0; p < n; ++p)
            rc2.push_back(U(rng));
        }
      const auto d = detail::split_form_direction(data, it, rc1, rc2);
      const auto z = block_size == 3 ? split_direction_by_direct_solve<3>(data, it, rc1, rc2)
                                     : split_direction_by_direct_solve<6>(data, it, rc1, rc2);
      std::vector<double> eliminated = d.du;
      for (const auto *part : {&d.da, &d.dlambda, &d.dx})
        eliminated.insert(eliminated.end(), part->begin(), part->end());
      ASSERT_EQ(eliminated.size(), z.size());
      ASSERT_EQ(d.dlambda.size(), m);
      const double scale = std::abs(*std::max_element(
          z.begin(), z.end(), [](double p, double q) { return std::abs(p) < std::abs(q); }));
      for (std::size_t k = 0; k < z.size(); ++k)
        EXPECT_NEAR(eliminated[k], z[k], 1e-10 * scale) << "block size " << n << ", unknown " << k;
    }
}

TEST_P(ConeInteriorPointForms, RejectsPointsOutsideItsScope)
{
  // mu = Bi = 0 (K_0 is a ray, without interior) is the fixed point's only; Bi > 0 (the truncated
  // cone, 16) and mu = 0 with Bi > 0 (Bingham) are the split form's too, not the whole form's.
  const bool split = GetParam() != 0.;
  for (const auto &[mu, Bi] : {std::pair{0., 0.}, std::pair{0.5, 0.1}, std::pair{0., 0.3}})
    {
      const ConeProblemData data = single_point_problem({-1., 0.2, 0.}, mu, Bi);
      ConeSolverOptions     options;
      options.method                    = ConeMethod::interior_point;
      options.interior_point.split_form = GetParam();
      ConeSolution solution;
      if (split ? mu + Bi == 0. : mu == 0. || Bi > 0.)
        EXPECT_THROW(solve_cone_problem(data, options, solution), std::invalid_argument)
            << mu << ", " << Bi;
      else
        EXPECT_TRUE(solve_cone_problem(data, options, solution).converged) << mu << ", " << Bi;
    }
}

TEST(ConeSplitInteriorPoint, TruncatedConesAgreeWithTheFixedPoint)
{
  // DP(mu, Bi) with Bi > 0 (the truncated cone K_{mu,Bi} of (16)), one point of it Bingham's (mu =
  // 0), in 2D and 3D: the split form, whose friction pair is (t, gamma_T) in K _|_ (Bi + mu
  // lambda_N, lambda_T) in K, finds the u of Cadoux's fixed point with the truncated cone
  // (4.5.2), and its lambda satisfies the law with gamma recomputed from u: by the library's
  // Alart-Curnier residual (valid for any Bi) and case by case, written out in the test. In 2D the
  // three points are on the cone's side (flowing), at its base's edge (lambda_N = 0, |lambda_T| =
  // Bi, dilating) and inside the radius at lambda_N = 0 (gamma_T = 0, dilating), each strictly
  // complementary. Tolerance 1e-6, not the 1e-7 of the Bi = 0 tests: in 2D the split form ends
  // at 4.9e-7, where its velocity matrix, whose block at the flowing point grows like lambda_N /
  // gamma_N (2e11 there), can no longer be factorised.
  for (const std::size_t block_size : {3, 6})
    {
      ConeProblemData data = coupled_random_problem(block_size, block_size == 3 ? 10 : 20);
      data.mu              = {0., 0.5, 0.8};
      data.Bi              = {0.2, 0.05, 0.5};
      ConeSolverOptions options;
      options.method    = ConeMethod::interior_point;
      options.residual  = ResidualKind::alart_curnier;
      options.tolerance = 1e-6;
      std::ostringstream log;
      options.log = &log;
      ConeSolution solution;
      const auto   stats = solve_cone_problem(data, options, solution);
      ASSERT_TRUE(stats.converged) << log.str();
      EXPECT_EQ(log.str().find("whole form"), std::string::npos) << log.str();

      std::vector<double> gamma;
      data.H.vmult(gamma, solution.u);
      EXPECT_LE(cone_residual(data, ResidualKind::alart_curnier, solution.lambda, gamma), 1e-6);
      expect_truncated_cone_law(data, block_size, solution.lambda, gamma, 1e-5);
      RecordProperty("residual_" + std::to_string(block_size), std::to_string(stats.residual));

      ConeSolverOptions reference_options;
      reference_options.inner_solver = InnerSolver::projected_gradient;
      reference_options.residual     = ResidualKind::alart_curnier;
      reference_options.tolerance    = 1e-9;
      ConeSolution reference;
      ASSERT_TRUE(solve_cone_problem(data, reference_options, reference).converged);
      for (std::size_t i = 0; i < solution.u.size(); ++i)
        EXPECT_NEAR(solution.u[i], reference.u[i], 1e-6) << "block size " << block_size;
      if (block_size == 3)
        {
          std::array<int, 3> cases{{0, 0, 0}}; // side, base edge, inside
          for (std::size_t i = 0; i < 3; ++i)
            {
              const double *l  = &solution.lambda[3 * i];
              const double  lT = std::hypot(l[1], l[2]), radius = data.Bi[i] + data.mu[i] * l[0];
              ++cases[radius - lT > 1e-5 ? 2 : (l[0] > 1e-5 ? 0 : 1)];
            }
          RecordProperty("side_edge_inside", std::to_string(cases[0]) + " " +
                                                 std::to_string(cases[1]) + " " +
                                                 std::to_string(cases[2]));
          EXPECT_EQ(cases, (std::array<int, 3>{{1, 1, 1}})) << "one point in each case";
        }
    }
}

TEST(ConeSolverStop, AStopRequestEndsEitherMethodWithItsBestIterate)
{
  // A stop request (Ctrl-C in the command line) ends the solve at its next check, like the time
  // limit: not converged, stats.interrupted set, and a solution that is the least-residual
  // iterate (its stored residual is that of lambda and gamma returned).
  // The fixed point is run with first-order (spg) and with interior-point steps.
  const ConeProblemData data = coupled_random_problem();
  for (const auto &[method, split_form, inner] :
       {std::tuple{ConeMethod::fixed_point, 0., InnerSolver::spg},
        std::tuple{ConeMethod::fixed_point, 0., InnerSolver::interior_point},
        std::tuple{ConeMethod::interior_point, 0., InnerSolver::spg},
        std::tuple{ConeMethod::interior_point, 1., InnerSolver::spg}})
    {
      ConeSolverOptions options;
      options.method                    = method;
      options.inner_solver              = inner;
      options.interior_point.split_form = split_form;
      options.tolerance      = 1e-14; // not reached in the two iterations allowed
      unsigned int polls     = 0;
      options.stop_requested = [&polls] { return ++polls > 2; };
      ConeSolution solution;
      const auto   stats = solve_cone_problem(data, options, solution);
      EXPECT_FALSE(stats.converged);
      EXPECT_TRUE(stats.interrupted);
      EXPECT_LE(stats.outer_iterations, 2U);
      EXPECT_DOUBLE_EQ(stats.residual,
                       cone_residual(data, options.residual, solution.lambda, solution.gamma));
      EXPECT_EQ(solution.u.size(), data.A.n_rows);
    }
}

TEST(ConeSolverStop, TheTimeLimitEndsAnInnerSolve)
{
  // Solver/Max seconds: the inner solves of the fixed point are given a tolerance they cannot
  // reach (inner factor 0: 1e-303; only an exact solution, which spg finds on this small problem,
  // ends one early) and tens of millions of iterations. The solve must end at the time limit
  // (0.1 s), not when the outer loop next looks at the clock: fewer inner iterations in all than
  // one inner solve may take (without the check one solve ran on to that cap). The bound of 2 s
  // on the time leaves a loaded machine twenty times the limit.
  const ConeProblemData data = coupled_random_problem();
  for (const InnerSolver inner :
       {InnerSolver::projected_gradient, InnerSolver::apgd, InnerSolver::spg})
    {
      ConeSolverOptions options;
      options.inner_solver           = inner;
      options.tolerance              = 1e-300;
      options.inner_tolerance_factor = 0.;
      options.max_inner_iterations   = std::numeric_limits<unsigned int>::max() / 64;
      options.max_seconds            = 0.1;
      ConeSolution solution;
      const auto   stats = solve_cone_problem(data, options, solution);
      EXPECT_TRUE(stats.timed_out) << to_string(inner);
      EXPECT_FALSE(stats.converged) << to_string(inner);
      EXPECT_LT(stats.inner_iterations, options.max_inner_iterations) << to_string(inner);
      EXPECT_LT(stats.time_solve, 2.) << to_string(inner);
      EXPECT_DOUBLE_EQ(stats.residual,
                       cone_residual(data, options.residual, solution.lambda, solution.gamma));
    }
}

TEST(ConeSolverStop, AStagnatingFixedPointEndsAsStalled)
{
  // A tolerance no iterate can reach (1e-300): the fixed point's residual falls to the level of
  // rounding and stays there. It ends as stalled (FixedPointTunables::stagnation_min_iterations)
  // once the least residual of the later half of its history is above half that of the earlier
  // half, long before its iteration limit, with its best iterate; with the rule switched off it
  // runs to that limit.
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.inner_solver         = InnerSolver::projected_gradient;
  options.tolerance            = 1e-300;
  options.max_outer_iterations = 100; // it stalls after 41 (measured)
  options.max_inner_iterations = 20;
  ConeSolution solution;
  auto         stats = solve_cone_problem(data, options, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_FALSE(stats.converged);
  EXPECT_FALSE(stats.timed_out);
  EXPECT_GE(stats.residual_history.size(), options.fixed_point.stagnation_min_iterations);
  EXPECT_LT(stats.outer_iterations, options.max_outer_iterations);
  EXPECT_NE(stats.stall_reason.find("the least residual of its last"), std::string::npos)
      << stats.stall_reason;
  // the rule's own test, recomputed from the history
  const auto &h    = stats.residual_history;
  const auto  half = h.begin() + h.size() / 2;
  EXPECT_GT(*std::min_element(half, h.end()), 0.5 * *std::min_element(h.begin(), half));
  EXPECT_DOUBLE_EQ(stats.residual, *std::min_element(h.begin(), h.end()));
  EXPECT_DOUBLE_EQ(stats.residual,
                   cone_residual(data, options.residual, solution.lambda, solution.gamma));
  // one iteration earlier the rule did not hold: it ends the solve at the first that it does
  const std::vector<double> before(h.begin(), h.end() - 1);
  if (before.size() >= options.fixed_point.stagnation_min_iterations)
    {
      const auto b = before.begin() + before.size() / 2;
      EXPECT_LE(*std::min_element(b, before.end()), 0.5 * *std::min_element(before.begin(), b));
    }

  options.fixed_point.stagnation_min_iterations = 0;
  solution                                      = ConeSolution(); // the same cold start
  stats                                         = solve_cone_problem(data, options, solution);
  EXPECT_FALSE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, options.max_outer_iterations);
}

TEST(ConeSolverStop, AStagnatingFixedPointWithInteriorPointStepsEndsAsStalled)
{
  // The same rule ends the fixed point whose steps are interior-point solves: on a tolerance no
  // iterate can reach, it stalls before its iteration limit, with its best iterate; with the rule
  // off it runs to that limit.
  const ConeProblemData data = coupled_random_problem();
  ConeSolverOptions     options;
  options.inner_solver         = InnerSolver::interior_point;
  options.tolerance            = 1e-300;
  // it stalls after 61 (measured): warm-started steps keep lowering the residual near
  // round-off for longer than cold ones, which stalled before 60
  options.max_outer_iterations = 100;
  ConeSolution solution;
  auto         stats = solve_cone_problem(data, options, solution);
  EXPECT_TRUE(stats.stalled);
  EXPECT_FALSE(stats.converged);
  EXPECT_LT(stats.outer_iterations, options.max_outer_iterations);
  EXPECT_GE(stats.residual_history.size(), options.fixed_point.stagnation_min_iterations);
  EXPECT_NE(stats.stall_reason.find("the least residual of its last"), std::string::npos)
      << stats.stall_reason;
  const HistoryHalves h = least_of_halves(stats.residual_history);
  EXPECT_GT(h.later_least, options.fixed_point.stagnation_ratio * h.earlier_least);
  EXPECT_DOUBLE_EQ(stats.residual, std::min(h.earlier_least, h.later_least));
  EXPECT_DOUBLE_EQ(stats.residual,
                   cone_residual(data, options.residual, solution.lambda, solution.gamma));

  options.fixed_point.stagnation_min_iterations = 0;
  solution                                      = ConeSolution();
  stats                                         = solve_cone_problem(data, options, solution);
  EXPECT_FALSE(stats.stalled);
  EXPECT_EQ(stats.outer_iterations, options.max_outer_iterations);
}

TEST(ConeSolverStop, TheStagnationTestSplitsTheHistoryInHalves)
{
  // least_of_halves on made-up histories: the later half takes the extra entry of an odd count,
  // a NaN counts as infinite wherever it stands, and an empty half has an infinite least.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case
  {
    std::vector<double> history;
    std::size_t         earlier, later;
    double              earlier_least, later_least;
  };
  const std::vector<Case> cases = {
      {{}, 0, 0, inf, inf},
      {{3.}, 0, 1, inf, 3.},
      {{4., 2.}, 1, 1, 4., 2.},
      {{5., 1., 3., 2., 4.}, 2, 3, 1., 2.}, // odd: 2 and 3
      {{1., 9., 8., 7.}, 2, 2, 1., 7.},     // the least of each half, not the last
      {{nan, 2., 3., 1.}, 2, 2, 2., 1.},    // a NaN first is not the least
      {{2., nan, nan, nan}, 2, 2, 2., inf}, // a later half of NaN never gains
      {{1e-3, 4e-4, 6e-4, 5e-4, 7e-4, 3e-4}, 3, 3, 4e-4, 3e-4}};
  for (const auto &c : cases)
    {
      const HistoryHalves h = least_of_halves(c.history);
      EXPECT_EQ(h.earlier, c.earlier) << c.history.size() << " entries";
      EXPECT_EQ(h.later, c.later) << c.history.size() << " entries";
      EXPECT_EQ(h.earlier_least, c.earlier_least) << c.history.size() << " entries";
      EXPECT_EQ(h.later_least, c.later_least) << c.history.size() << " entries";
    }
  // The last case is one the rule (ratio 0.5) calls stagnating: 3e-4 is above half of 4e-4.
  const HistoryHalves h = least_of_halves(cases.back().history);
  EXPECT_GT(h.later_least, FixedPointTunables().stagnation_ratio * h.earlier_least);
}

TEST(ConeSolverStop, PredictionEndsWhereTheNextIterationWouldEndPastTheTimeLimit)
{
  // The interior point's iterations (one factorisation each) cannot be interrupted, so its loop
  // asks SolveMonitor::finished(true) (cone_interior_point.cc), which ends where the next
  // iteration, at the last one's duration (at the first, the setup's), would end past Solver/Max
  // seconds. Elapsed times are given, not measured, so that the test does not depend on the
  // machine.
  ConeSolverOptions options;
  options.tolerance   = 1e-300;
  options.max_seconds = 10.;
  // elapsed time of each iterate and whether the loop ends there with and without prediction
  struct Step
  {
    double elapsed;
    bool   ends_predicted, ends_plain;
  };
  const std::vector<Step> steps = {{3., false, false},  // setup 3 s: 3 + 3 <= 10
                                   {6., false, false},  // 6 + 3 <= 10
                                   {8., false, false},  // 8 + 2 = 10, not past
                                   {9.5, true, false}}; // 9.5 + 1.5 > 10, though 9.5 < 10
  for (const bool predict : {true, false})
    {
      ConeSolverStats      stats;
      detail::SolveMonitor monitor(options, stats);
      for (const Step &step : steps)
        {
          monitor.record(1., step.elapsed);
          const bool ends = monitor.finished(predict);
          EXPECT_EQ(ends, predict ? step.ends_predicted : step.ends_plain)
              << "predict " << predict << " at " << step.elapsed << " s";
          EXPECT_EQ(stats.timed_out, ends);
          ++stats.outer_iterations;
        }
    }
  // At the first iterate the setup's duration is the prediction: 6 s of setup, 6 + 6 > 10.
  {
    ConeSolverStats      stats;
    detail::SolveMonitor monitor(options, stats);
    monitor.record(1., 6.);
    EXPECT_TRUE(monitor.finished(true));
    EXPECT_TRUE(stats.timed_out);
  }
  // Without a limit nothing times out, however long an iteration takes.
  options.max_seconds = 0.;
  ConeSolverStats      stats;
  detail::SolveMonitor monitor(options, stats);
  monitor.record(1., 1e9);
  EXPECT_FALSE(monitor.finished(true));
  EXPECT_FALSE(stats.timed_out);
}

TEST(ConeProblemIO, DumpAndLoadRoundTrip)
{
  ConeProblemData data;
  data.block_size = 3;
  data.A          = dense_to_csr(identity(3));
  data.H          = dense_to_csr({{1., 2., 0.}, {0., 1., 0.}, {3., 0., 1.}});
  data.l          = {1., 2., 3.};
  data.k          = {0.5, 0., -1.};
  data.mu         = {0.4};
  data.Bi         = {0.1};
  data.gamma_scale       = {250.};
  const auto dump        = [](const ConeProblemData &d) {
    std::ostringstream out(std::ios::binary);
    write_cone_problem(d, out);
    return out.str();
  };
  const auto load = [](const std::string &bytes) {
    std::istringstream in(bytes, std::ios::binary);
    return read_cone_problem(in);
  };
  const std::string     bytes = dump(data);
  const ConeProblemData back  = load(bytes);
  EXPECT_EQ(back.H.value, data.H.value);
  EXPECT_EQ(back.H.column, data.H.column);
  EXPECT_EQ(back.l, data.l);
  EXPECT_EQ(back.k, data.k);
  EXPECT_EQ(back.mu, data.mu);
  EXPECT_EQ(back.Bi, data.Bi);
  EXPECT_EQ(back.gamma_scale, data.gamma_scale);

  // A dump from before session 12 ends after Bi: it loads, with no scale (all 1).
  EXPECT_TRUE(load(bytes.substr(0, bytes.size() - 2 * sizeof(std::uint64_t))) // size 1, one double
                  .gamma_scale.empty());
  // A truncated one, or another file, is refused.
  EXPECT_THROW(load(bytes.substr(0, bytes.size() / 2)), std::runtime_error);
  EXPECT_THROW(load("not a dump at all"), std::runtime_error);
  // A scale per point or none: anything else is refused.
  data.gamma_scale = {1., 2.};
  EXPECT_THROW(load(dump(data)), std::runtime_error);
  // Cone blocks of 3 (2D) or 6 (3D) components, nothing else: one point of 1-component blocks
  // is size-consistent with a 1-row H, and was accepted before.
  data.H           = dense_to_csr({{1., 0., 0.}});
  data.k           = {0.};
  data.gamma_scale = {};
  data.block_size  = 1;
  EXPECT_THROW(load(dump(data)), std::runtime_error);
  EXPECT_THROW(cone_residual(data, ResidualKind::fischer_burmeister, {0.}, {0.}),
               std::invalid_argument);
}

TEST(ConeSolverNames, TheCaseFilesNamesParseAndOthersAreRejected)
{
  EXPECT_EQ(parse_cone_method("fixed point"), ConeMethod::fixed_point);
  EXPECT_EQ(parse_cone_method("interior point"), ConeMethod::interior_point);
  EXPECT_THROW(parse_cone_method("interior-point"), std::invalid_argument);
  for (const InnerSolver s : {InnerSolver::projected_gradient, InnerSolver::apgd, InnerSolver::spg,
                              InnerSolver::interior_point})
    EXPECT_EQ(parse_inner_solver(to_string(s)), s);
  EXPECT_THROW(parse_inner_solver("sor"), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(SplitAndWhole, ConeInteriorPointForms, ::testing::Values(1., 0.),
                         [](const auto &info) { return info.param != 0. ? "split" : "whole"; });

INSTANTIATE_TEST_SUITE_P(InnerSolvers, ConeSolverAllInner,
                         ::testing::Values(InnerSolver::projected_gradient, InnerSolver::apgd,
                                           InnerSolver::spg));

TEST(ConeSolverStop, ANanIterateNeverReplacesTheBestOne)
{
  // The solvers keep the iterate for which record() returns true and return it when they stop
  // without converging: a NaN iterate (a diverged step) must not replace a finite one.
  ConeSolverOptions    options;
  ConeSolverStats      stats;
  detail::SolveMonitor monitor(options, stats);
  const double         nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(monitor.record(1e-2, 0.));
  EXPECT_TRUE(monitor.record(1e-5, 1.));
  EXPECT_FALSE(monitor.record(nan, 2.));
  EXPECT_FALSE(monitor.record(1e-3, 3.));
  EXPECT_EQ(monitor.least_residual(), 1e-5);
  // A NaN first iterate is kept until any number replaces it.
  ConeSolverStats      stats2;
  detail::SolveMonitor monitor2(options, stats2);
  EXPECT_TRUE(monitor2.record(nan, 0.));
  EXPECT_TRUE(monitor2.record(nan, 1.));
  EXPECT_TRUE(monitor2.record(0.5, 2.));
  EXPECT_FALSE(monitor2.record(nan, 3.));
  EXPECT_EQ(monitor2.least_residual(), 0.5);
}

namespace
{
  // A velocity operator with a rigid motion left free is singular. The dp model checks the
  // boundary conditions against the rigid motions first (a Gram matrix); CholmodSolver's own
  // refusal is the fallback, and the dp model turns it into a bad-input error on `Boundary
  // conditions`. It must throw NotPositiveDefinite (not factorise, not return garbage) for a
  // semidefinite matrix, whose null vector is such a motion, and for an indefinite one.
  TEST(CholmodSolver, RefusesAnOperatorThatIsNotPositiveDefinite)
  {
    const std::vector<std::vector<std::vector<double>>> singular = {
        {{1., 1.}, {1., 1.}},                       // null vector (1, -1)
        {{2., 0., 0.}, {0., 0., 0.}, {0., 0., 3.}}, // a free unknown
        {{1., 2.}, {2., 1.}}};                      // indefinite
    for (const auto &M : singular)
      {
        try
          {
            CholmodSolver solver(dense_to_csr(M));
            ADD_FAILURE() << "a matrix that is not positive definite was factorised: " << M[0][0]
                          << ", " << M[0][1] << ", ...";
          }
        catch (const NotPositiveDefinite &e)
          {
            EXPECT_NE(std::string(e.what()).find("rigid motion"), std::string::npos) << e.what();
          }
      }
    // and a positive definite neighbour is accepted and solved
    CholmodSolver       solver(dense_to_csr({{2., 1.}, {1., 2.}}));
    std::vector<double> x;
    solver.solve(x, {3., 3.});
    EXPECT_NEAR(x[0], 1., 1e-14);
    EXPECT_NEAR(x[1], 1., 1e-14);
  }
} // namespace

// The sparse LU used by the interior point and by ngf's Newton steps: it solves M x = b for an
// unsymmetric M (not M^T x = b: a CSR matrix is handed to UMFPACK as the CSC storage of M^T),
// refactorises with new values on the same pattern, and reports a singular matrix as
// SingularMatrix, which ngf answers by cutting its increment, distinct from its other failures.
TEST(UmfpackSolver, SolvesUnsymmetricSystemsAndReportsASingularMatrixAsSuch)
{
  const std::vector<std::vector<double>> M       = {{4., 1., 0.}, {2., 5., 1.}, {0., 3., 6.}};
  const std::vector<double>              x_exact = {1., -2., 3.};
  for (const bool diagonal_pivoting : {false, true})
    {
      UmfpackSolver lu(diagonal_pivoting);
      for (const double scale : {1., -2.5}) // a second factorisation reuses the symbolic analysis
        {
          CsrMatrix A = dense_to_csr(M);
          for (double &a : A.value)
            a *= scale;
          std::vector<double> b, x;
          A.vmult(b, x_exact);
          lu.factorize(A);
          lu.solve(x, b);
          for (std::size_t i = 0; i < x.size(); ++i)
            EXPECT_NEAR(x[i], x_exact[i], 1e-14) << "row " << i << ", scale " << scale;
        }
      // The same pattern with a zero second column: singular, found on the kept analysis.
      CsrMatrix S = dense_to_csr(M);
      for (std::size_t k = 0; k < S.column.size(); ++k)
        if (S.column[k] == 1)
          S.value[k] = 0.;
      EXPECT_THROW(lu.factorize(S), SingularMatrix);
      // ngf's path after a singular Jacobian: no solve with the failed factors, then a new
      // factorisation on the same pattern that solves.
      std::vector<double> b, x;
      EXPECT_THROW(lu.solve(x, b), std::logic_error);
      const CsrMatrix A = dense_to_csr(M);
      A.vmult(b, x_exact);
      lu.factorize(A);
      lu.solve(x, b);
      for (std::size_t i = 0; i < x.size(); ++i)
        EXPECT_NEAR(x[i], x_exact[i], 1e-14) << "row " << i << " after the singular matrix";
    }
  // A pattern UMFPACK refuses (a row's columns out of order) is another failure, named.
  CsrMatrix unsorted = dense_to_csr(M);
  std::swap(unsorted.column[0], unsorted.column[1]);
  std::swap(unsorted.value[0], unsorted.value[1]);
  UmfpackSolver lu;
  try
    {
      lu.factorize(unsorted);
      ADD_FAILURE() << "a matrix with unsorted columns was factorised";
    }
  catch (const SingularMatrix &)
    {
      ADD_FAILURE() << "a matrix with unsorted columns was reported as singular";
    }
  catch (const std::runtime_error &e)
    {
      EXPECT_NE(std::string(e.what()).find("invalid matrix"), std::string::npos) << e.what();
    }
}
