// The Newton driver (solvers/newton.h) on small two-field systems with known solutions: its
// quadratic rate with fresh Jacobians, the line search where the full step overshoots, modified
// steps that reuse a factorisation only while they contract, and its failures.
#include "solvers/newton.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <sstream>

using namespace granflow::solvers;

namespace
{
  struct Vec2
  {
    std::array<double, 2> v{};
    void
    add(const double alpha, const Vec2 &y)
    {
      v[0] += alpha * y.v[0];
      v[1] += alpha * y.v[1];
    }
  };

  using R2 = std::array<double, 2>;
  using M2 = std::array<R2, 2>;

  R2
  r2(const double a, const double b)
  {
    R2 r;
    r[0] = a;
    r[1] = b;
    return r;
  }

  M2
  m2(const double a, const double b, const double c, const double d)
  {
    M2 m;
    m[0] = r2(a, b);
    m[1] = r2(c, d);
    return m;
  }

  Vec2
  vec(const double a, const double b)
  {
    Vec2 v;
    v.v = r2(a, b);
    return v;
  }

  /// r(x) with its Jacobian, one unknown per field; the scale of each field's residual is 1.
  class TwoFields : public NewtonProblem<Vec2>
  {
  public:
    using Residual = std::function<R2(const Vec2 &)>;
    using Jacobian = std::function<M2(const Vec2 &)>;

    TwoFields(Residual r, Jacobian J, const Vec2 &start)
        : r(std::move(r))
        , J(std::move(J))
        , x(start)
    {
    }

    Vec2 &
    iterate() override
    {
      return x;
    }

    FieldResiduals
    residual(const bool with_jacobian) override
    {
      ++evaluations;
      last = r(x);
      if (with_jacobian)
        assembled = J(x);
      const R2 s = scale(x);
      return {{std::abs(last[0]), std::abs(last[1])}, {s[0], s[1]}};
    }

    bool
    correction(Vec2 &dx, const bool factorize) override
    {
      if (factorize)
        {
          factorized = assembled;
          ++factorizations;
        }
      const auto  &M   = factorized;
      const double det = M[0][0] * M[1][1] - M[0][1] * M[1][0];
      if (det == 0.)
        return false;
      dx.v[0] = -(M[1][1] * last[0] - M[0][1] * last[1]) / det;
      dx.v[1] = -(-M[1][0] * last[0] + M[0][0] * last[1]) / det;
      return true;
    }

    std::vector<CorrectionSize>
    correction_sizes(const Vec2 &dx) const override
    {
      return {{std::abs(dx.v[0]), std::abs(x.v[0])}, {std::abs(dx.v[1]), std::abs(x.v[1])}};
    }

    void
    make_admissible(Vec2 &y) override
    {
      if (nonnegative_second)
        y.v[1] = std::max(y.v[1], 0.);
    }

    Residual                             r;
    Jacobian                             J;
    Residual scale = [](const Vec2 &) { return r2(1., 1.); }; // of each field's residual
    Vec2                                 x;
    std::array<double, 2>                last{};
    std::array<std::array<double, 2>, 2> assembled{}, factorized{};
    unsigned int                         evaluations = 0, factorizations = 0;
    bool                                 nonnegative_second = false;
  };

  /// x0^2 + x1 = 3, x0 - x1 = -1: a coupled system with a regular root at (1, 2).
  TwoFields
  coupled(const Vec2 &start)
  {
    return TwoFields(
        [](const Vec2 &y) { return r2(y.v[0] * y.v[0] + y.v[1] - 3., y.v[0] - y.v[1] + 1.); },
        [](const Vec2 &y) { return m2(2. * y.v[0], 1., 1., -1.); }, start);
  }

  NewtonOptions
  pure_newton(const double tolerance)
  {
    NewtonOptions o;
    o.tolerance           = tolerance;
    o.reuse_factorization = false;
    o.max_iterations      = 30;
    return o;
  }
} // namespace

TEST(Newton, FreshJacobiansConvergeQuadratically)
{
  TwoFields          problem = coupled(vec(1.3, 1.6));
  NewtonOptions      options = pure_newton(1e-13);
  std::ostringstream log;
  options.log = &log;
  NewtonSolver<Vec2> newton(options);
  const NewtonStats  stats = newton.solve(problem, 7);
  ASSERT_TRUE(stats.converged) << log.str();
  EXPECT_NEAR(problem.x.v[0], 1., 1e-12);
  EXPECT_NEAR(problem.x.v[1], 2., 1e-12);
  EXPECT_EQ(problem.factorizations, stats.iterations);
  // Quadratic rate: once in the asymptotic range, R_{k+1} <= C R_k^2 with a C of order one.
  const auto  &h       = stats.history;
  unsigned int checked = 0;
  for (std::size_t k = 0; k + 1 < h.size(); ++k)
    {
      const double R = merit(h[k].residual), R_next = merit(h[k + 1].residual);
      if (R < 1e-2 && R_next > 1e-15)
        {
          EXPECT_LE(R_next, 10. * R * R) << "iteration " << k;
          ++checked;
        }
    }
  EXPECT_GE(checked, 1u);
  // The log's table opens each line with the label.
  EXPECT_NE(log.str().find("     7     0"), std::string::npos) << log.str();
}

TEST(Newton, TheLineSearchTamesAnOvershootingStep)
{
  // atan(x0) = 0 from x0 = 3: the full Newton step goes to -9.5 and diverges; x1 = 1 is linear.
  TwoFields          problem([](const Vec2 &y) { return r2(std::atan(y.v[0]), y.v[1] - 1.); },
                    [](const Vec2 &y) { return m2(1. / (1. + y.v[0] * y.v[0]), 0., 0., 1.); },
                    vec(3., 0.));
  std::ostringstream log;
  NewtonOptions      options = pure_newton(1e-12);
  options.log                = &log;
  const NewtonStats stats    = NewtonSolver<Vec2>(options).solve(problem, 0);
  ASSERT_TRUE(stats.converged) << log.str();
  EXPECT_NEAR(problem.x.v[0], 0., 1e-12);
  EXPECT_NE(log.str().find("line search step"), std::string::npos);

  NewtonOptions no_halving = options;
  no_halving.max_halvings  = 0; // every full step taken: the classic divergence
  problem.x                = vec(3., 0.);
  EXPECT_FALSE(NewtonSolver<Vec2>(no_halving).solve(problem, 0).converged);
}

TEST(Newton, AReusedFactorizationIsKeptOnlyWhileItContracts)
{
  // Near the root, steps with the first Jacobian contract fast enough: one factorisation serves
  // the whole solve, and the next solve from a nearby start as well.
  TwoFields     problem       = coupled(vec(1.001, 2.001));
  NewtonOptions options       = pure_newton(1e-12);
  options.reuse_factorization = true;
  NewtonSolver<Vec2> newton(options);
  ASSERT_TRUE(newton.solve(problem, 0).converged);
  EXPECT_EQ(problem.factorizations, 1u);
  problem.x               = vec(1.002, 1.999);
  const NewtonStats again = newton.solve(problem, 1);
  ASSERT_TRUE(again.converged);
  EXPECT_EQ(problem.factorizations, 1u);
  EXPECT_FALSE(again.history.front().fresh);

  // Far from it, the old Jacobian's step does not contract four times: it is undone and the
  // Jacobian factorised afresh.
  problem.x             = vec(5., 6.);
  const NewtonStats far = newton.solve(problem, 2);
  ASSERT_TRUE(far.converged);
  EXPECT_GT(problem.factorizations, 1u);
  EXPECT_FALSE(far.history[0].fresh);
  EXPECT_TRUE(far.history[1].fresh);
  EXPECT_EQ(far.history[0].residual, far.history[1].residual); // the step was undone
}

TEST(Newton, AStaleFactorizationsSmallStepIsNoConvergence)
{
  // A stiff problem leaves the factorisation of J = diag(1e12, 1); the next problem, with its root
  // at x0 = 3, gets from it a correction of 2e-12 of x0, negligible by the rule that ends a solve
  // at the round-off floor. That rule holds for fresh Jacobians only: the stale step does not
  // contract the residual, is undone, and the new Jacobian leads to the root.
  TwoFields     problem([](const Vec2 &y) { return r2(1e12 * (y.v[0] - 1.), y.v[1] - 2.); },
                    [](const Vec2 &) { return m2(1e12, 0., 0., 1.); }, vec(1.5, 2.));
  NewtonOptions options       = pure_newton(1e-6);
  options.reuse_factorization = true;
  NewtonSolver<Vec2> newton(options);
  ASSERT_TRUE(newton.solve(problem, 0).converged);
  problem.r               = [](const Vec2 &y) { return r2(y.v[0] - 3., y.v[1] - 2.); };
  problem.J               = [](const Vec2 &) { return m2(1., 0., 0., 1.); };
  const NewtonStats stats = newton.solve(problem, 1);
  ASSERT_TRUE(stats.converged);
  EXPECT_FALSE(stats.history.front().fresh);
  EXPECT_NEAR(problem.x.v[0], 3., 1e-12);
}

TEST(Newton, ANegligibleCorrectionEndsTheSolveAtTheRoundOffFloor)
{
  // r_0 = 1e12 (x0 - 1) at x0 = 1 + 1e-14 is 1e-2, far above the tolerance, but its correction is
  // 1e-14 of x0: the solve ends there, converged, without another iteration.
  TwoFields         problem([](const Vec2 &y) { return r2(1e12 * (y.v[0] - 1.), y.v[1] - 2.); },
                    [](const Vec2 &) { return m2(1e12, 0., 0., 1.); }, vec(1. + 1e-14, 2.));
  const NewtonStats stats = NewtonSolver<Vec2>(pure_newton(1e-6)).solve(problem, 0);
  ASSERT_TRUE(stats.converged);
  EXPECT_EQ(stats.iterations, 0u);
  ASSERT_EQ(stats.history.size(), 1u);
  EXPECT_GT(stats.history[0].residual[0], 1e-6);
  EXPECT_LE(stats.history[0].correction[0], 1e-10);
}

TEST(Newton, TheLineSearchJudgesATrialWithTheScalesOfItsStart)
{
  // atan(x0) = 0 from x0 = 3 with the residual's scale 1 + x0^2: the full step to -9.5 has a
  // larger |r| but a far larger scale. Judged with its own scale it would pass, and the iterates
  // run off to x0 = 9e8, where |r| / (1 + x0^2) is below the tolerance: a false convergence.
  TwoFields problem([](const Vec2 &y) { return r2(std::atan(y.v[0]), y.v[1] - 1.); },
                    [](const Vec2 &y) { return m2(1. / (1. + y.v[0] * y.v[0]), 0., 0., 1.); },
                    vec(3., 0.));
  problem.scale           = [](const Vec2 &y) { return r2(1. + y.v[0] * y.v[0], 1.); };
  const NewtonStats stats = NewtonSolver<Vec2>(pure_newton(1e-12)).solve(problem, 0);
  ASSERT_TRUE(stats.converged);
  EXPECT_NEAR(problem.x.v[0], 0., 1e-10);
}

TEST(Newton, AStepMustDecreaseTheMeritSufficiently)
{
  // Near atan's Newton 2-cycle (x0 = +-1.3917) the full step barely decreases |r|. Armijo's
  // condition rejects it and the halved step converges in 2 iterations; accepting any decrease
  // would creep along the cycle (16 iterations).
  TwoFields         problem([](const Vec2 &y) { return r2(std::atan(y.v[0]), y.v[1] - 1.); },
                    [](const Vec2 &y) { return m2(1. / (1. + y.v[0] * y.v[0]), 0., 0., 1.); },
                    vec(1.39174, 1.));
  const NewtonStats stats = NewtonSolver<Vec2>(pure_newton(1e-12)).solve(problem, 0);
  ASSERT_TRUE(stats.converged);
  EXPECT_LE(stats.iterations, 4u);
}

TEST(Newton, FailuresEndTheSolveUnconverged)
{
  // A singular Jacobian (at x0 = 0 the first row of J vanishes) is reported, not stepped over.
  TwoFields          singular([](const Vec2 &y) { return r2(y.v[0] * y.v[0] - 1., y.v[1]); },
                     [](const Vec2 &y) { return m2(2. * y.v[0], 0., 0., 1.); }, vec(0., 1.));
  std::ostringstream log;
  NewtonOptions      options = pure_newton(1e-12);
  options.log                = &log;
  NewtonStats stats          = NewtonSolver<Vec2>(options).solve(singular, 0);
  EXPECT_FALSE(stats.converged);
  EXPECT_TRUE(stats.singular);
  EXPECT_NE(log.str().find("singular Jacobian"), std::string::npos);

  // A residual that is not a number ends the solve at once.
  TwoFields nan([](const Vec2 &) { return r2(1., std::nan("")); },
                [](const Vec2 &) { return m2(1., 0., 0., 1.); }, vec(0., 0.));
  stats = NewtonSolver<Vec2>(options).solve(nan, 0);
  EXPECT_FALSE(stats.converged);
  EXPECT_EQ(stats.iterations, 0u);

  // The iteration limit: each iteration is one correction.
  NewtonOptions two  = options;
  two.max_iterations = 2;
  TwoFields far      = coupled(vec(3., -2.));
  stats              = NewtonSolver<Vec2>(two).solve(far, 0);
  EXPECT_FALSE(stats.converged);
  EXPECT_EQ(stats.iterations, 2u);
  EXPECT_EQ(stats.history.size(), 3u);
  EXPECT_TRUE(std::isnan(stats.history.back().correction[0]));
}

TEST(Newton, AStopRequestEndsTheSolveBeforeTheNextCorrection)
{
  // A Ctrl-C (NewtonOptions::stop_requested, asked before each correction) ends the solve
  // unconverged and interrupted, after the corrections already taken; a solve that converges
  // first is not interrupted.
  NewtonOptions options     = pure_newton(1e-13);
  unsigned int  asked       = 0;
  options.stop_requested    = [&asked] { return ++asked > 2; }; // after two corrections
  TwoFields         problem = coupled(vec(1.3, 1.6));
  const NewtonStats stats   = NewtonSolver<Vec2>(options).solve(problem, 0);
  EXPECT_FALSE(stats.converged);
  EXPECT_TRUE(stats.interrupted);
  EXPECT_EQ(stats.iterations, 2u);
  EXPECT_EQ(problem.factorizations, 2u);
  EXPECT_EQ(asked, 3u);

  TwoFields at_root       = coupled(vec(1., 2.));
  options.stop_requested  = [] { return true; };
  const NewtonStats there = NewtonSolver<Vec2>(options).solve(at_root, 0);
  EXPECT_TRUE(there.converged);
  EXPECT_FALSE(there.interrupted);
}

TEST(Newton, IteratesAreMadeAdmissible)
{
  // r = (x0 - 1, x1 + 1) has its root at x1 = -1, outside x1 >= 0: every step is projected back,
  // so the residual of x1 never falls below 1 and the solve ends unconverged at x1 = 0.
  TwoFields problem([](const Vec2 &y) { return r2(y.v[0] - 1., y.v[1] + 1.); },
                    [](const Vec2 &) { return m2(1., 0., 0., 1.); }, vec(0., 0.5));
  problem.nonnegative_second = true;
  const NewtonStats stats    = NewtonSolver<Vec2>(pure_newton(1e-12)).solve(problem, 0);
  EXPECT_FALSE(stats.converged);
  EXPECT_EQ(problem.x.v[1], 0.);
  EXPECT_NEAR(problem.x.v[0], 1., 1e-12);
  for (const NewtonIterate &it : stats.history)
    EXPECT_GE(it.residual[1], 1.);
}
