// Primal-dual interior point on the *split form* of the DP(mu, Bi) problem (35) of Daviet &
// Bertails-Descoubes 2016 (docs/solvers.md, "the split form"). The law of Corollary 1,
//   lambda in K_mu,  gamma_hat = gamma + mu ||gamma_T|| e_N in K_{1/mu},  lambda . gamma_hat = 0,
// is the same as the two complementarities
//   gamma_N >= 0  _|_  lambda_N >= 0                                  (unilateral
//   incompressibility) x = (t, gamma_T) in K_1  _|_  y = (mu lambda_N, lambda_T) in K_1  (maximal
//   dissipation)
// with an auxiliary t (t = ||gamma_T|| wherever lambda != 0): gamma_hat in K_{1/mu} is gamma_N >=
// 0, and lambda . gamma_hat = lambda_N gamma_N + (mu lambda_N ||gamma_T|| + lambda_T . gamma_T) is
// a sum of two terms >= 0. Unlike cone_interior_point.cc, whose Newton steps linearise De Saxce's
// ||gamma_T||, the central path here is bilinear: a_i b_i = tau and x_i o y_i = tau e, with the
// slacks a = gamma_N(u), x_T = gamma_T(u) held by residuals r_N = a - gamma_N(u), r_T = x_T -
// gamma_T(u), and b = lambda_N.
//
// Each iteration is a Mehrotra predictor-corrector step with Nesterov-Todd scaling of the cone pair
// (W x = W^-1 y = v, G = W^2). Eliminating the slacks and the stress point by point,
//   dlambda = f - M dgamma,  M = [[c, 0], [mu c G_0T / G_00, S]],  c = b / a,
//   S = G_TT - G_T0 G_0T / G_00,
// leaves the velocity system (A + H^T M H) du = -r_m + H^T f (r_m = A u - H^T lambda - l),
// unsymmetric through the friction cone's radius mu lambda_N (the incompressibility multiplier),
// factorised by UMFPACK at every iteration. tau = gap / (2 n): each pair has degree 1.
// Bi > 0 (the truncated cone K_{mu,Bi} of (16), 4.5) only shifts y: y = (Bi + mu lambda_N,
// lambda_T) in K_1 is ||lambda_T|| <= Bi + mu lambda_N, and the split is the same (at lambda_N = 0
// the friction pair still holds gamma_T against lambda_T). Its directions dy = (mu dlambda_N,
// dlambda_T) are unchanged; mu = 0 (Bingham) is allowed where Bi > 0, since y then keeps an
// interior.
#include "solvers/cholmod_solver.h"
#include "solvers/cone_problem.h"
#include "solvers/interior_point_loop.h"
#include "solvers/point_blocks.h"
#include "solvers/soc.h"
#include "solvers/solve_monitor.h"
#include "solvers/umfpack_solver.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <type_traits>

namespace granflow::solvers
{
  namespace
  {
    using Vector = std::vector<double>;
    using Clock  = std::chrono::steady_clock;

    template <std::size_t n> class SplitInteriorPoint
    {
      using S      = detail::Soc<n>;
      using Matrix = typename S::Matrix;

    public:
      using Block = typename S::Block;

      SplitInteriorPoint(const ConeProblemData &data, const ConeSolverOptions &options)
          : data(data)
          , options(options)
          , n_u(data.A.n_rows)
          , n_points(data.n_points())
          , m(n_points * n)
          , blocks(data)
          , A_inv(data.A)
      {
        detail::check_interior_point_scope(data, detail::InteriorPointForm::split);
        blocks.build_reduced_pattern();
        // UMFPACK's own refinement (2 steps by default) changes neither the iterations nor the
        // residual's first 6 digits on the 673-vertex silo and the default cylinder, and costs a
        // quarter of their time.
        lu.set_refinement_steps(0);
      }

      ConeSolverStats
      solve(ConeSolution &solution)
      {
        const auto t0 = Clock::now();
        // The starting point: u = 0, lambda = e_N, the slacks a = 1 and x = e (off every cone's
        // boundary; the residuals r_N, r_T take up the difference).
        u.assign(n_u, 0.);
        lambda.assign(m, 0.);
        a.assign(n_points, 1.);
        x.assign(m, 0.);
        for (std::size_t i = 0; i < n_points; ++i)
          lambda[i * n] = x[i * n] = 1.;
        if (options.log)
          *options.log << "  interior point on the split form (Mehrotra, Nesterov-Todd scaling)\n"
                       << "   iter      residual           gap       primal         dual      step"
                          "      time[s]\n";
        return detail::run_interior_point(*this, options, solution, t0);
      }

      // The iterate's side of detail::run_interior_point.
      double
      residual()
      {
        evaluate(u, lambda, a, x);
        // The residual of (35) at lambda, with the velocity of the momentum balance (35a): the
        // iterate's u satisfies it only in the limit (r_m -> 0).
        balanced_velocity(lambda, u_lambda, gamma_lambda);
        return cone_residual(data, options.residual, lambda, gamma_lambda);
      }

      void
      keep(ConeSolution &solution) const
      {
        solution.u      = u_lambda;
        solution.lambda = lambda;
        solution.gamma  = gamma_lambda;
      }

      void
      log_columns(std::ostream &log) const
      {
        log << std::setw(14) << gap << std::setw(13) << primal_residual() << std::setw(13)
            << detail::norm_inf(r_m);
      }

      double
      newton_step()
      {
        return mehrotra_step();
      }

      void
      stepped(unsigned int)
      {
      }

      const std::string &
      failure() const
      {
        return factorization_failure;
      }

      unsigned int
      n_factorizations() const
      {
        return factorizations;
      }

    private:
      double
      primal_residual() const
      {
        const double normal = detail::norm_inf(r_N), tangential = detail::norm_inf(r_T);
        return std::isnan(tangential) ? tangential : std::max(normal, tangential); // keeps a NaN
      }

      Block
      block(const Vector &x, const std::size_t i) const
      {
        Block b;
        std::copy_n(x.begin() + i * n, n, b.begin());
        return b;
      }

      /// y = (Bi + mu lambda_N, lambda_T), the stress in the coordinates of K_1: y in K_1 is
      /// lambda's friction condition ||lambda_T|| <= Bi + mu lambda_N, the truncated cone
      /// K_{mu,Bi} of (16) with lambda_N >= 0 held by the other pair.
      Block
      y_block(const Vector &lambda, const std::size_t i) const
      {
        Block y = dy_block(lambda, i);
        y[0] += data.Bi[i];
        return y;
      }

      /// dy = (mu dlambda_N, dlambda_T): y's change along a change dlambda of the stress.
      Block
      dy_block(const Vector &dlambda, const std::size_t i) const
      {
        Block y = block(dlambda, i);
        y[0] *= data.mu[i];
        return y;
      }

      /// u = A^-1 (H^T lambda + l) and gamma = H u + k.
      void
      balanced_velocity(const Vector &lambda, Vector &u, Vector &gamma) const
      {
        Vector rhs;
        data.H.Tvmult(rhs, lambda);
        for (std::size_t k = 0; k < n_u; ++k)
          rhs[k] += data.l[k];
        A_inv.solve(u, rhs);
        data.H.vmult(gamma, u);
        for (std::size_t k = 0; k < m; ++k)
          gamma[k] += data.k[k];
      }

      /// With gamma(u) = H u + k: r_m = A u - H^T lambda - l, r_N = a - gamma_N, r_T = x_T -
      /// gamma_T (stored per point as blocks of n with r_T[i n] unused), and gap = a . b + x . y.
      void
      evaluate(const Vector &u, const Vector &lambda, const Vector &a, const Vector &x)
      {
        Vector gamma_u;
        data.H.vmult(gamma_u, u);
        for (std::size_t k = 0; k < m; ++k)
          gamma_u[k] += data.k[k];
        Vector Htl;
        data.A.vmult(r_m, u);
        data.H.Tvmult(Htl, lambda);
        for (std::size_t k = 0; k < n_u; ++k)
          r_m[k] -= Htl[k] + data.l[k];
        r_N.resize(n_points);
        r_T.assign(m, 0.);
        gap = 0.;
        for (std::size_t i = 0; i < n_points; ++i)
          {
            r_N[i] = a[i] - gamma_u[i * n];
            for (std::size_t j = 1; j < n; ++j)
              r_T[i * n + j] = x[i * n + j] - gamma_u[i * n + j];
            gap += a[i] * lambda[i * n] + S::dot(block(x, i), y_block(lambda, i));
          }
      }

      /// Largest step keeping a, lambda_N, x and y interior, per point.
      double
      max_step(const Vector &a, const Vector &lambda, const Vector &x, const Vector &da,
               const Vector &dlambda, const Vector &dx) const
      {
        double t = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < n_points; ++i)
          {
            if (da[i] < 0.)
              t = std::min(t, -a[i] / da[i]);
            if (dlambda[i * n] < 0.)
              t = std::min(t, -lambda[i * n] / dlambda[i * n]);
            t = std::min({t, S::max_step(block(x, i), block(dx, i)),
                          S::max_step(y_block(lambda, i), dy_block(dlambda, i))});
          }
        return t;
      }

    public:
      /// The iterate (u, lambda, a, x), the residuals and the gap evaluated at it.
      void
      set_iterate(const detail::SplitIterate &iterate)
      {
        u      = iterate.u;
        lambda = iterate.lambda;
        a      = iterate.a;
        x      = iterate.x;
        evaluate(u, lambda, a, x);
      }

      /// Per point, at the current iterate: the scaling (v = W x, G = W^2), c = b / a and the
      /// reduced block M; then the velocity matrix A + H^T M H is factorised. False (and
      /// `factorization_failure` set) if UMFPACK cannot factorise it.
      bool
      scale_and_factorize()
      {
        W.resize(n_points);
        W_inv.resize(n_points);
        G.resize(n_points);
        M.resize(n_points);
        v.resize(n_points);
        c.resize(n_points);
        for (std::size_t i = 0; i < n_points; ++i)
          {
            S::nesterov_todd(block(x, i), y_block(lambda, i), W[i], W_inv[i]);
            G[i]       = S::multiply(W[i], W[i]);
            v[i]       = S::apply(W[i], block(x, i));
            c[i]       = lambda[i * n] / a[i];
            M[i]       = Matrix{};
            M[i][0][0] = c[i];
            for (std::size_t p = 1; p < n; ++p)
              {
                M[i][p][0] = data.mu[i] * c[i] * G[i][p][0] / G[i][0][0];
                for (std::size_t q = 1; q < n; ++q)
                  M[i][p][q] = G[i][p][q] - G[i][p][0] * G[i][0][q] / G[i][0][0];
              }
          }
        try
          {
            lu.factorize(blocks.reduced(M));
            ++factorizations;
          }
        catch (const std::runtime_error &e)
          {
            factorization_failure = e.what(); // named in the stall reason
            return false;
          }
        return true;
      }

      /// The Newton direction (du, da, dlambda, dx) of the linearised split form for the
      /// complementarity right-hand sides rc1 (a_i dlambda_N,i + lambda_N,i da_i = rc1_i) and
      /// rc2 (v o (W dx + W^-1 dy) = rc2, dy = (mu dlambda_N, dlambda_T)), with the momentum
      /// balance A du - H^T dlambda = -r_m and the slack relations da - dgamma_N = -r_N,
      /// dx_T - dgamma_T = -r_T; after scale_and_factorize(). False if du is not finite.
      bool
      direction(const Vector &rc1, const std::vector<Block> &rc2)
      {
        std::vector<Block> Wq(n_points);
        f.resize(m);
        for (std::size_t i = 0; i < n_points; ++i)
          {
            Wq[i]           = S::apply(W[i], S::arrow_solve(v[i], rc2[i]));
            const double fN = rc1[i] / a[i] + c[i] * r_N[i];
            const double y0 = (Wq[i][0] - data.mu[i] * fN) / G[i][0][0];
            f[i * n]        = fN;
            for (std::size_t p = 1; p < n; ++p)
              {
                double fp = Wq[i][p] - G[i][p][0] * y0;
                for (std::size_t q = 1; q < n; ++q)
                  fp += M[i][p][q] * r_T[i * n + q];
                f[i * n + p] = fp;
              }
          }
        Vector Htf, rhs(n_u), dgamma;
        data.H.Tvmult(Htf, f);
        for (std::size_t k = 0; k < n_u; ++k)
          rhs[k] = Htf[k] - r_m[k];
        lu.solve(du, rhs);
        data.H.vmult(dgamma, du);
        da.resize(n_points);
        dlambda.resize(m);
        dx.resize(m);
        for (std::size_t i = 0; i < n_points; ++i)
          {
            const Block g    = block(dgamma, i);
            da[i]            = g[0] - r_N[i];
            const double dlN = rc1[i] / a[i] - c[i] * da[i];
            Block        d; // dx = (dt, dx_T)
            for (std::size_t p = 1; p < n; ++p)
              d[p] = g[p] - r_T[i * n + p];
            double s = Wq[i][0] - data.mu[i] * dlN;
            for (std::size_t p = 1; p < n; ++p)
              s -= G[i][0][p] * d[p];
            d[0] = s / G[i][0][0];
            // dy = W q - G dx; its first entry is mu dlambda_N by the choice of dt
            const Block Gd = S::apply(G[i], d);
            dlambda[i * n] = dlN;
            for (std::size_t p = 1; p < n; ++p)
              dlambda[i * n + p] = Wq[i][p] - Gd[p];
            std::copy(d.begin(), d.end(), dx.begin() + i * n);
          }
        for (const double d : du)
          if (!std::isfinite(d))
            return false;
        return true;
      }

      detail::SplitDirection
      last_direction() const
      {
        return {du, da, dlambda, dx};
      }

    private:
      /// One Mehrotra predictor-corrector step from the current iterate; returns the step length
      /// taken (0: none).
      double
      mehrotra_step()
      {
        if (!scale_and_factorize())
          return 0.;
        const double       tau = gap / (2. * static_cast<double>(n_points));
        Vector             rc1(n_points);
        std::vector<Block> rc2(n_points);
        for (std::size_t i = 0; i < n_points; ++i) // predictor: the affine direction
          {
            rc1[i] = -a[i] * lambda[i * n];
            rc2[i] = S::product(v[i], v[i]);
            for (double &r : rc2[i])
              r = -r;
          }
        if (!direction(rc1, rc2))
          return 0.;
        const double t_affine   = std::min(1., max_step(a, lambda, x, da, dlambda, dx));
        double       gap_affine = 0.;
        for (std::size_t i = 0; i < n_points; ++i)
          {
            gap_affine += (a[i] + t_affine * da[i]) * (lambda[i * n] + t_affine * dlambda[i * n]);
            Block       xa = block(x, i), ya = y_block(lambda, i);
            const Block dxa = block(dx, i), dya = dy_block(dlambda, i);
            for (std::size_t p = 0; p < n; ++p)
              {
                xa[p] += t_affine * dxa[p];
                ya[p] += t_affine * dya[p];
              }
            gap_affine += S::dot(xa, ya);
          }
        const double centering = std::pow(std::clamp(gap_affine / gap, 0., 1.),
                                          options.interior_point.centering_exponent);
        for (std::size_t i = 0; i < n_points; ++i) // corrector
          {
            rc1[i] += centering * tau - da[i] * dlambda[i * n];
            const Block second =
                S::product(S::apply(W[i], block(dx, i)), S::apply(W_inv[i], dy_block(dlambda, i)));
            for (std::size_t p = 0; p < n; ++p)
              rc2[i][p] -= second[p];
            rc2[i][0] += centering * tau;
          }
        if (!direction(rc1, rc2))
          return 0.;
        double t = std::min(1., options.interior_point.step_fraction *
                                    max_step(a, lambda, x, da, dlambda, dx));
        // Rounding can still put a block on the boundary: halve until every block is interior.
        const auto interior = [&](const double t) {
          for (std::size_t i = 0; i < n_points; ++i)
            {
              Block       xs = block(x, i), ys = y_block(lambda, i);
              const Block dxs = block(dx, i), dys = dy_block(dlambda, i);
              for (std::size_t p = 0; p < n; ++p)
                {
                  xs[p] += t * dxs[p];
                  ys[p] += t * dys[p];
                }
              if (!(a[i] + t * da[i] > 0.) || !S::interior(xs) || !S::interior(ys))
                return false;
            }
          return true;
        };
        t = detail::halve_until_interior(t, interior);
        if (t == 0.)
          return 0.;
        for (std::size_t k = 0; k < n_u; ++k)
          u[k] += t * du[k];
        for (std::size_t i = 0; i < n_points; ++i)
          a[i] += t * da[i];
        for (std::size_t k = 0; k < m; ++k)
          {
            lambda[k] += t * dlambda[k];
            x[k] += t * dx[k];
          }
        return t;
      }

      const ConeProblemData   &data;
      const ConeSolverOptions &options;
      const std::size_t        n_u, n_points, m;
      detail::PointBlocks      blocks;
      CholmodSolver            A_inv; // for the residual at lambda
      UmfpackSolver            lu{true};
      unsigned int             factorizations = 0;
      std::string              factorization_failure;  // UMFPACK's message, if it failed
      Vector                   u, lambda, a, x;        // the iterate
      Vector                   r_m, r_N, r_T;          // set by evaluate()
      Vector                   u_lambda, gamma_lambda;
      double                   gap = 0.;
      // The step's scaling and reduced blocks (scale_and_factorize()), and the direction
      std::vector<Matrix> W, W_inv, G, M;
      std::vector<Block>  v;
      Vector              c, f;
      Vector              du, da, dlambda, dx;
    };
  } // namespace

  namespace detail
  {
    SplitDirection
    split_form_direction(const ConeProblemData &data, const SplitIterate &iterate,
                         const std::vector<double> &rc1, const std::vector<double> &rc2)
    {
      const auto compute = [&](auto &&method) {
        using Block          = typename std::decay_t<decltype(method)>::Block;
        const std::size_t  n = data.block_size;
        std::vector<Block> rc2_blocks(data.n_points());
        for (std::size_t i = 0; i < data.n_points(); ++i)
          std::copy_n(rc2.begin() + i * n, n, rc2_blocks[i].begin());
        method.set_iterate(iterate);
        if (!method.scale_and_factorize() || !method.direction(rc1, rc2_blocks))
          throw std::runtime_error("split_form_direction: no finite direction");
        return method.last_direction();
      };
      const ConeSolverOptions options;
      if (data.block_size == 3)
        return compute(SplitInteriorPoint<3>(data, options));
      if (data.block_size == 6)
        return compute(SplitInteriorPoint<6>(data, options));
      throw std::invalid_argument("split_form_direction: block size must be 3 (2D) or 6 (3D)");
    }
  } // namespace detail

  ConeSolverStats
  solve_cone_problem_split_interior_point(const ConeProblemData   &data,
                                          const ConeSolverOptions &options, ConeSolution &solution)
  {
    return detail::construct_and_solve<SplitInteriorPoint>(data, options, solution);
  }
} // namespace granflow::solvers
