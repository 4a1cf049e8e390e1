// Cadoux fixed point for the DP(mu, Bi) cone problem, its steps by projected-gradient inner
// solvers or (mu > 0, Bi = 0) by the interior point with De Saxce's term frozen (4.4.2).
// Daviet & Bertails-Descoubes 2016: Algorithm 1 (4.4.1), SOCQP (37)/(43), PG Algorithm 2 (4.4.3),
// truncated cone for Bi > 0 (4.5.2). APGD: Nesterov (1983) as adapted by Heyn (2013), with the
// gradient restart of O'Donoghue & Candes. SPG: Barzilai-Borwein (1988) with the nonmonotone line
// search of Birgin, Martinez & Raydan, as adapted to SOCQP by Tasora (2013).
#include "rheology/drucker_prager.h"
#include "solvers/cholmod_solver.h"
#include "solvers/cone_problem.h"
#include "solvers/dense.h"
#include "solvers/interior_point_loop.h"
#include "solvers/solve_monitor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace granflow::solvers
{
  namespace
  {
    using Vector = std::vector<double>;
    using Clock  = std::chrono::steady_clock;

    double
    seconds_since(const Clock::time_point t0)
    {
      return std::chrono::duration<double>(Clock::now() - t0).count();
    }

    double
    dot(const Vector &a, const Vector &b)
    {
      double s = 0.;
      for (std::size_t i = 0; i < a.size(); ++i)
        s += a[i] * b[i];
      return s;
    }

    /// x += t y
    void
    add(Vector &x, const double t, const Vector &y)
    {
      for (std::size_t i = 0; i < x.size(); ++i)
        x[i] += t * y[i];
    }

    /// W = H A^{-1} H^T applied matrix-free (Daviet (36)); counts back-solves.
    class DelassusOperator
    {
    public:
      DelassusOperator(const ConeProblemData &data, const CholmodSolver &A_inv)
        : data(data)
        , A_inv(A_inv)
      {
      }

      void
      apply(Vector &out, const Vector &lambda)
      {
        data.H.Tvmult(rhs, lambda);
        A_inv.solve(velocity, rhs);
        data.H.vmult(out, velocity);
        ++applications;
      }

      /// u = A^{-1} (H^T lambda + l) (35a)
      void
      velocity_of(Vector &u, const Vector &lambda) const
      {
        Vector r;
        data.H.Tvmult(r, lambda);
        add(r, 1., data.l);
        A_inv.solve(u, r);
      }

      unsigned int applications = 0;

    private:
      const ConeProblemData &data;
      const CholmodSolver   &A_inv;
      Vector                 rhs, velocity;
    };

    /// Anderson acceleration (type II, depth m) of the fixed point s = F(s) of Algorithm 1:
    /// s <- F(s) - sum_j c_j (F(s_j+1) - F(s_j)), with c minimising || f - sum_j c_j (f_j+1 - f_j)
    /// ||, f = F(s) - s. The Cadoux map F is not a contraction in general (4.4.1); plain iteration
    /// can cycle where mu is large. s stays >= 0.
    class AndersonAcceleration
    {
    public:
      AndersonAcceleration(const unsigned int depth, const double regularization)
          : depth(depth)
          , regularization(regularization)
      {
      }

      void
      update(Vector &s, const Vector &F_s)
      {
        Vector f = F_s;
        add(f, -1., s);
        if (!f_previous.empty())
          {
            Vector dF = f, dG = F_s;
            add(dF, -1., f_previous);
            add(dG, -1., F_previous);
            dFs.push_back(std::move(dF));
            dGs.push_back(std::move(dG));
            if (dFs.size() > depth)
              {
                dFs.erase(dFs.begin());
                dGs.erase(dGs.begin());
              }
          }
        f_previous = f;
        F_previous = F_s;
        s          = F_s;
        const std::size_t k = dFs.size();
        if (k == 0)
          return;
        // Normal equations of the small least-squares problem, Tikhonov-regularised.
        std::vector<std::vector<double>> M(k, std::vector<double>(k + 1, 0.));
        for (std::size_t a = 0; a < k; ++a)
          {
            for (std::size_t b = 0; b < k; ++b)
              M[a][b] = dot(dFs[a], dFs[b]);
            M[a][a] *= 1. + regularization;
            M[a][k] = dot(dFs[a], f);
          }
        std::vector<double> c;
        if (!solve_augmented(M, c))
          return;
        for (std::size_t a = 0; a < k; ++a)
          add(s, -c[a], dGs[a]);
        for (double &v : s)
          v = std::max(v, 0.);
      }

      /// Forgets the history: the next update is a plain fixed-point step.
      void
      reset()
      {
        dFs.clear();
        dGs.clear();
        f_previous.clear();
        F_previous.clear();
      }

    private:
      unsigned int        depth;
      double              regularization;
      std::vector<Vector> dFs, dGs;
      Vector              f_previous, F_previous;
    };

    /// Upper estimate of ||W|| (W symmetric positive semi-definite): power iterations, times a
    /// margin (FixedPointTunables).
    double
    estimate_norm(DelassusOperator &W, const std::size_t m, const FixedPointTunables &tunables)
    {
      Vector x(m, 1.), y;
      double norm = 0.;
      for (unsigned int k = 0; k < tunables.norm_estimate_iterations; ++k)
        {
          const double x_norm = std::sqrt(dot(x, x));
          if (x_norm == 0.)
            break;
          for (double &v : x)
            v /= x_norm;
          W.apply(y, x);
          norm = std::sqrt(dot(y, y));
          std::swap(x, y);
        }
      return norm > 0. ? tunables.norm_margin * norm : 1.;
    }

    /// The product of cones K_{mu_i, Bi_i} over the constraint points, blocks of n components.
    template <std::size_t n> class ConeProduct
    {
    public:
      explicit ConeProduct(const ConeProblemData &data)
        : data(data)
      {
      }

      std::array<double, n>
      block(const Vector &x, const std::size_t i) const
      {
        std::array<double, n> b;
        std::copy_n(x.begin() + i * n, n, b.begin());
        return b;
      }

      void
      project(Vector &x) const
      {
        for (std::size_t i = 0; i < data.n_points(); ++i)
          {
            const auto p =
                rheology::project_onto_truncated_cone(block(x, i), data.mu[i], data.Bi[i]);
            std::copy(p.begin(), p.end(), x.begin() + i * n);
          }
      }

      /// Natural-map residual of the inner SOCQP, max_i || lambda_i - Pi_K(lambda_i - c_i g_i) ||,
      /// with the outer residual's gamma_scale c_i (its zeros are the same for any c_i > 0).
      double
      projected_gradient_norm(const Vector &lambda, const Vector &g) const
      {
        double r = 0.;
        for (std::size_t i = 0; i < data.n_points(); ++i)
          {
            const double          c = data.gamma_scale.empty() ? 1. : data.gamma_scale[i];
            std::array<double, n> y;
            for (std::size_t j = 0; j < n; ++j)
              y[j] = lambda[i * n + j] - c * g[i * n + j];
            const auto p = rheology::project_onto_truncated_cone(y, data.mu[i], data.Bi[i]);
            double     s = 0.;
            for (std::size_t j = 0; j < n; ++j)
              s += (lambda[i * n + j] - p[j]) * (lambda[i * n + j] - p[j]);
            r = std::max(r, std::sqrt(s));
          }
        return r;
      }

      double
      residual(const ResidualKind kind, const Vector &lambda, const Vector &gamma) const
      {
        double r = 0.;
        for (std::size_t i = 0; i < data.n_points(); ++i)
          {
            const auto l = block(lambda, i);
            auto       g = block(gamma, i);
            if (!data.gamma_scale.empty())
              for (auto &gj : g)
                gj *= data.gamma_scale[i];
            const auto   f  = (kind == ResidualKind::fischer_burmeister && data.Bi[i] == 0.)
                                  ? rheology::f_FB(l, g, data.mu[i])
                                  : rheology::f_AC(l, g, data.mu[i], data.Bi[i]);
            const double fi = rheology::norm(f);
            if (std::isnan(fi))
              return fi; // std::max would drop it, and a NaN iterate would pass as converged
            r = std::max(r, fi);
          }
        return r;
      }

    private:
      const ConeProblemData &data;
    };

    /// State of one inner solve of min 1/2 x^T W x + x^T q over the cone product.
    struct Quadratic
    {
      Vector x, Wx, g; // g = W x + q
      double J = 0.;
      void
      refresh(const Vector &q)
      {
        g = Wx;
        add(g, 1., q);
        J = 0.5 * dot(x, Wx) + dot(x, q);
      }
    };

    template <std::size_t n> class InnerSolverImpl
    {
    public:
      InnerSolverImpl(const ConeProduct<n> &K, DelassusOperator &W,
                      const ConeSolverOptions &options,
                      const double             lipschitz)
        : max_iterations(options.max_inner_iterations) // declared first
        , K(K)
        , W(W)
        , options(options)
        , lipschitz(lipschitz)
        , step(1. / lipschitz)
      {
      }

      unsigned int max_iterations; // per call; raised by the outer loop when it stalls
      /// options.max_seconds after the start of the solve: an inner solve ends there, and the
      /// outer loop, which sees the time limit passed, ends with it.
      Clock::time_point deadline = Clock::time_point::max();

      /// Minimises from the warm start in `state`; returns the iteration count.
      unsigned int
      solve(Quadratic &state, const Vector &q, const double tolerance)
      {
        unsigned int it = 0;
        switch (options.inner_solver)
          {
            case InnerSolver::projected_gradient:
              it = solve_pg(state, q, tolerance);
              break;
            case InnerSolver::apgd:
              it = solve_apgd(state, q, tolerance);
              break;
            case InnerSolver::spg:
              it = solve_spg(state, q, tolerance);
              break;
            case InnerSolver::interior_point: // solve_fixed_point_interior_point's own loop
              throw std::logic_error("the first-order inner solver cannot be the interior point");
          }
        last_residual = K.projected_gradient_norm(state.x, state.g);
        return it;
      }

      double last_residual = 0.; // natural-map residual of the last inner solve

    private:
      /// A stop request or the time limit; the outer loop sees either at its next check and ends
      /// there.
      bool
      stop_requested() const
      {
        return (options.stop_requested && options.stop_requested()) || Clock::now() >= deadline;
      }

      /// d = Pi_K(x - step g) - x
      void
      projected_direction(Vector &d, const Quadratic &s, const double step) const
      {
        d = s.x;
        add(d, -step, s.g);
        K.project(d);
        add(d, -1., s.x);
      }

      /// Algorithm 2 with the step 1/L (L >= ||W||), followed by an exact line search along the
      /// projected direction (t <= 1 keeps the iterate feasible); one application of W per
      /// iteration.
      unsigned int
      solve_pg(Quadratic &s, const Vector &q, const double tolerance)
      {
        Vector       d, Wd;
        unsigned int it = 0;
        for (; it < max_iterations; ++it)
          {
            if (K.projected_gradient_norm(s.x, s.g) <= tolerance || stop_requested())
              break;
            projected_direction(d, s, 1. / lipschitz);
            W.apply(Wd, d);
            // Exact line search; where the descent g.d is lost in rounding, the plain step of
            // Algorithm 2 (t = 1).
            const double gd = dot(s.g, d), dWd = dot(d, Wd);
            const double t  = (gd < 0. && dWd > 0.) ? std::min(1., -gd / dWd) : 1.;
            add(s.x, t, d);
            add(s.Wx, t, Wd);
            s.refresh(q);
          }
        return it;
      }

      /// Nesterov acceleration with backtracking on the Lipschitz estimate L and gradient restart.
      unsigned int
      solve_apgd(Quadratic &s, const Vector &q, const double tolerance)
      {
        double L = std::max(1. / step, options.fixed_point.apgd_min_lipschitz_fraction * lipschitz);
        double theta   = 1.;
        Quadratic    y = s, x_new;
        Vector       diff;
        unsigned int it = 0;
        for (; it < max_iterations; ++it)
          {
            if (K.projected_gradient_norm(s.x, s.g) <= tolerance || stop_requested())
              break;
            for (;;)
              {
                x_new.x = y.x;
                add(x_new.x, -1. / L, y.g);
                K.project(x_new.x);
                W.apply(x_new.Wx, x_new.x);
                x_new.refresh(q);
                diff = x_new.x;
                add(diff, -1., y.x);
                if (x_new.J <=
                    y.J + dot(y.g, diff) + 0.5 * L * dot(diff, diff) + 1e-14 * std::abs(y.J))
                  break;
                L *= 2.;
              }
            const double theta_new = 0.5 * theta * (std::sqrt(theta * theta + 4.) - theta);
            const double beta      = theta * (1. - theta) / (theta * theta + theta_new);
            diff                   = x_new.x;
            add(diff, -1., s.x);
            if (dot(y.g, diff) > 0.) // restart when the momentum points uphill
              {
                y     = x_new;
                theta = 1.;
              }
            else
              {
                y.x = x_new.x;
                add(y.x, beta, diff);
                y.Wx = x_new.Wx;
                add(y.Wx, beta, x_new.Wx);
                add(y.Wx, -beta, s.Wx);
                y.refresh(q);
                theta = theta_new;
              }
            s = std::move(x_new);
            L *= options.fixed_point.apgd_lipschitz_decrease;
          }
        step = 1. / L;
        return it;
      }

      /// Spectral projected gradient: Barzilai-Borwein step, nonmonotone Armijo search along the
      /// projected direction. The objective is quadratic, so the search costs no extra
      /// application of W: one per iteration.
      unsigned int
      solve_spg(Quadratic &s, const Vector &q, const double tolerance)
      {
        const unsigned int     memory   = options.fixed_point.spg_memory;
        const double           armijo   = options.fixed_point.spg_armijo;
        // relative to the safe step 1/||W||: W scales with Re (A with 1/Re), an absolute bound
        // would cap the BB step below 1/||W|| at small Re (and leave std::clamp's bounds reversed)
        const double max_step = std::max(options.fixed_point.spg_max_step, 1.) / lipschitz;
        std::vector<double>    J_history{s.J};
        Vector                 d, Wd;
        unsigned int           it = 0;
        for (; it < max_iterations; ++it)
          {
            if (K.projected_gradient_norm(s.x, s.g) <= tolerance || stop_requested())
              break;
            projected_direction(d, s, step);
            W.apply(Wd, d);
            const double gd = dot(s.g, d), dWd = dot(d, Wd);
            const double J_max = *std::max_element(J_history.begin(), J_history.end());
            double       t     = 1.;
            // (where g.d >= 0 the descent is lost in rounding: take the projected step)
            while (gd < 0. && s.J + t * gd + 0.5 * t * t * dWd > J_max + armijo * t * gd &&
                   t > 1e-10)
              // safeguarded quadratic interpolation: on a quadratic it is the exact minimiser
              t = dWd > 0. ? std::clamp(-gd / dWd, 0.1 * t, 0.5 * t) : 0.5 * t;
            add(s.x, t, d);
            add(s.Wx, t, Wd);
            s.refresh(q);
            J_history.push_back(s.J);
            if (J_history.size() > memory)
              J_history.erase(J_history.begin());
            const double sy = t * t * dWd, ss = t * t * dot(d, d);
            // BB step, bounded below by 1/L: a collapsed step would stall in rounding.
            step = sy > 0. ? std::clamp(ss / sy, 1. / lipschitz, max_step) : max_step;
          }
        return it;
      }

      const ConeProduct<n>    &K;
      DelassusOperator        &W;
      const ConeSolverOptions &options;
      const double             lipschitz; // upper estimate of ||W||
      double                   step;      // kept across calls: the warm start of the step length
    };

    /// The next s of the fixed point from the strain rates gamma of the last step: F(s)_i = mu_i
    /// || gamma_{i,T} || (Algorithm 1), or its Anderson extrapolation once a step has been taken.
    template <std::size_t n>
    void
    next_s(const ConeProblemData &data, const ConeProduct<n> &K, const Vector &gamma,
           const ConeSolverOptions &options, const unsigned int outer_iterations,
           AndersonAcceleration &anderson, Vector &s, Vector &F_s)
    {
      for (std::size_t i = 0; i < data.n_points(); ++i)
        F_s[i] = data.mu[i] * rheology::norm_T(K.block(gamma, i));
      if (options.anderson_depth > 0 && outer_iterations > 0)
        anderson.update(s, F_s);
      else
        s = F_s;
    }

    /// Whether the fixed point stagnates (FixedPointTunables::stagnation_min_iterations): the
    /// least residual of the later half of its history is above stagnation_ratio times that of
    /// the earlier half. If so, `stats` is marked stalled, with the reason in words.
    bool
    stagnated(ConeSolverStats &stats, const FixedPointTunables &tune)
    {
      const std::vector<double> &history = stats.residual_history;
      if (tune.stagnation_min_iterations == 0 ||
          history.size() < std::max(tune.stagnation_min_iterations, 2u))
        return false;
      const HistoryHalves h = least_of_halves(history);
      if (!(h.later_least > tune.stagnation_ratio * h.earlier_least))
        return false;
      std::ostringstream s;
      s << std::setprecision(3) << "the least residual of its last " << h.later << " iterates, "
        << h.later_least << ", is above " << tune.stagnation_ratio << " times that of the "
        << h.earlier << " before them, " << h.earlier_least;
      stats.stalled      = true;
      stats.stall_reason = s.str();
      return true;
    }

    template <std::size_t n>
    ConeSolverStats
    solve_blocks(const ConeProblemData &data, const ConeSolverOptions &options,
                 ConeSolution &solution)
    {
      ConeSolverStats stats;
      const auto      t0 = Clock::now();
      CholmodSolver   A_inv(data.A);
      stats.time_factorize = seconds_since(t0);

      DelassusOperator   W(data, A_inv);
      ConeProduct<n>     K(data);
      InnerSolverImpl<n> inner(K, W, options,
                               estimate_norm(W, data.n_points() * n, options.fixed_point));

      const std::size_t m = data.n_points() * n;
      // w = H A^{-1} l + k (36)
      Vector w, Al;
      A_inv.solve(Al, data.l);
      data.H.vmult(w, Al);
      add(w, 1., data.k);

      Quadratic state;
      state.x = solution.lambda.size() == m ? solution.lambda : Vector(m, 0.);
      K.project(state.x);

      if (options.log)
        *options.log << "  Cadoux fixed point (" << to_string(options.inner_solver) << ")\n"
                     << "   iter      residual   inner   W-apps      time[s]   inner-residual\n";
      Vector     q(m), gamma(m), s(data.n_points(), 0.), F_s(data.n_points(), 0.);
      const FixedPointTunables &tune = options.fixed_point;
      AndersonAcceleration      anderson(options.anderson_depth, tune.anderson_regularization);
      double       inner_factor          = options.inner_tolerance_factor;
      unsigned int last_inner_iterations = 0, stalls = 0;
      Vector     best_lambda, best_gamma; // the iterate of least residual so far
      detail::SolveMonitor monitor(options, stats);
      const auto t1 = Clock::now();
      if (options.max_seconds > 0. && options.max_seconds < 1e9) // (beyond: no limit, no overflow)
        inner.deadline = t1 + std::chrono::ceil<Clock::duration>(
                                  std::chrono::duration<double>(options.max_seconds));
      for (;;)
        {
          // gamma = W lambda + w (Algorithm 1, first line)
          W.apply(state.Wx, state.x);
          gamma = state.Wx;
          add(gamma, 1., w);
          if (monitor.record(K.residual(options.residual, state.x, gamma), seconds_since(t1)))
            {
              best_lambda   = state.x;
              best_gamma    = gamma;
            }
          if (options.log)
            *options.log << std::setw(7) << stats.outer_iterations << std::setw(14)
                         << std::scientific << std::setprecision(4) << stats.residual
                         << std::setw(8) << stats.inner_iterations << std::setw(9) << W.applications
                         << std::setw(13) << std::fixed << std::setprecision(3)
                         << stats.time_history.back() << std::setw(17) << std::scientific
                         << std::setprecision(4) << inner.last_residual << std::endl
                         << std::defaultfloat;
          if (monitor.finished())
            break;
          if (stagnated(stats, tune))
            break;
          // No progress: the extrapolation (built on inexact evaluations of F) is dropped first;
          // if the plain step stalls too, the inner solves are the suspects: one that hit its
          // iteration cap gets a higher cap, one that reached its tolerance a tighter tolerance
          // (the inner natural-map residual and the outer residual weigh the components
          // differently).
          const bool stalled =
              stats.outer_iterations > 0 &&
              stats.residual >
                  tune.stall_ratio * *std::min_element(stats.residual_history.begin(),
                                                       stats.residual_history.end() - 1);
          stalls = stalled ? stalls + 1 : 0;
          if (stalled)
            anderson.reset();
          if (stalls >= tune.stalls_before_tightening)
            {
              if (last_inner_iterations >= inner.max_iterations)
                inner.max_iterations = std::min(
                    2 * inner.max_iterations, tune.max_inner_growth * options.max_inner_iterations);
              else
                inner_factor = std::max(0.1 * inner_factor, tune.min_inner_tolerance_factor);
            }
          // the next s, and q = w + (s; 0)   (37)
          next_s(data, K, gamma, options, stats.outer_iterations, anderson, s, F_s);
          q = w;
          for (std::size_t i = 0; i < data.n_points(); ++i)
            q[i * n] += s[i];
          state.refresh(q);
          const double inner_tolerance = std::max(inner_factor * stats.residual,
                                                  tune.inner_tolerance_floor * options.tolerance);
          last_inner_iterations = inner.solve(state, q, inner_tolerance);
          stats.inner_iterations += last_inner_iterations;
          ++stats.outer_iterations;
        }
      stats.time_solve            = seconds_since(t1);
      stats.operator_applications = W.applications;
      // Not converged: the fixed point is not monotone (4.4.1), so the last iterate need not be the
      // best one; the iterate of least residual is returned.
      stats.residual  = monitor.least_residual();
      solution.lambda = std::move(best_lambda);
      solution.gamma  = std::move(best_gamma);
      W.velocity_of(solution.u, solution.lambda);
      return stats;
    }

    /// Cadoux's fixed point whose convex steps (37) are solved by the whole-form interior point
    /// with s frozen (4.4.2, the method of Table 2's interior-point row, there without Anderson:
    /// anderson_depth = 0). As in solve_blocks, it starts from lambda = 0 (u = A^{-1} l), each
    /// step is solved to inner_tolerance_factor times the outer residual and s is extrapolated by
    /// Anderson. Unlike solve_blocks, a step whose residual does not fall keeps the extrapolation's
    /// history: the steps are accurate, and dropping it there (measured on the 673-vertex silo)
    /// left the iteration at 1.3e-5 after 111 steps where it converges in 36. The interior point
    /// starts afresh at each step (it cannot use a warm start). The loop itself starts, as
    /// solve_blocks does, from the stress in `solution` if it has one of the problem's size (its
    /// first s is then mu ||gamma_T|| of that stress's velocity), and from lambda = 0 otherwise.
    /// solve_interior_point starts it so from a stalled interior point's best iterate
    /// (docs/solvers.md).
    template <std::size_t n>
    ConeSolverStats
    solve_fixed_point_interior_point(const ConeProblemData &data, const ConeSolverOptions &options,
                                     ConeSolution &solution)
    {
      if (!detail::interior_point_handles(data, detail::InteriorPointForm::whole))
        throw std::invalid_argument("the fixed point's interior-point steps need mu > 0 and Bi = 0 "
                                    "at every constraint point (use pg, apgd or spg steps)");
      const std::size_t    n_points = data.n_points();
      const ConeProduct<n> K(data);
      ConeSolverStats   stats;
      const auto        t0 = Clock::now();
      // Each iterate's velocity is that of its stress by the momentum balance (35a), u = A^{-1}
      // (l + H^T lambda), and gamma = H u + k: a step's interior point satisfies (35a) only in
      // its limit, and its solves end at 0.1 of the outer residual.
      const CholmodSolver    A_inv(data.A);
      const DelassusOperator W(data, A_inv);
      const auto             balance = [&](ConeSolution &it) {
        W.velocity_of(it.u, it.lambda);
        data.H.vmult(it.gamma, it.u);
        add(it.gamma, 1., data.k);
      };
      // The starting iterate: the caller's stress, or none (the velocity of the load alone).
      ConeSolution step;
      const bool   from_zero = solution.lambda.size() != n_points * n;
      step.lambda            = from_zero ? Vector(n_points * n, 0.) : solution.lambda;
      balance(step);
      stats.time_factorize = seconds_since(t0);

      if (options.log)
        *options.log << "  Cadoux fixed point (interior point)\n"
                     << "   iter      residual   inner      time[s]   inner-residual\n";
      Vector               s(n_points, 0.), F_s(n_points, 0.);
      AndersonAcceleration anderson(options.anderson_depth,
                                    options.fixed_point.anderson_regularization);
      detail::SolveMonitor monitor(options, stats);
      ConeSolverOptions    inner = options;
      inner.log                  = nullptr;
      inner.progress             = nullptr;
      inner.max_outer_iterations = options.max_inner_iterations;
      double     inner_residual  = 0.;
      const auto t1              = Clock::now();
      for (;;)
        {
          if (monitor.record(cone_residual(data, options.residual, step.lambda, step.gamma),
                             seconds_since(t1)))
            solution = step;
          if (options.log)
            *options.log << std::setw(7) << stats.outer_iterations << std::setw(14)
                         << std::scientific << std::setprecision(4) << stats.residual
                         << std::setw(8) << stats.inner_iterations << std::setw(13) << std::fixed
                         << std::setprecision(3) << stats.time_history.back() << std::setw(17)
                         << std::scientific << std::setprecision(4) << inner_residual << std::endl
                         << std::defaultfloat;
          // An inner solve cut short by the time limit returns a poor step: none is started that
          // would, at the last one's duration, end past it.
          if (monitor.finished(true))
            break;
          if (stagnated(stats, options.fixed_point)) // as the first-order steps (solve_blocks)
            break;
          next_s(data, K, step.gamma, options, stats.outer_iterations, anderson, s, F_s);
          inner.tolerance = std::max(options.inner_tolerance_factor * stats.residual,
                                     options.fixed_point.inner_tolerance_floor * options.tolerance);
          if (options.max_seconds > 0.)
            inner.max_seconds = std::max(options.max_seconds - seconds_since(t1), 1e-3);
          // Each step is given the last iterate as its warm start
          // (InteriorPointTunables::warm_start_shift), the first one too unless that is the
          // stress-free start, far from any step's solution.
          if (from_zero && stats.outer_iterations == 0)
            step.u.clear();
          const ConeSolverStats in = solve_frozen_cone_problem_interior_point(data, s, inner, step);
          balance(step);
          inner_residual           = in.residual;
          stats.inner_iterations += in.outer_iterations;
          stats.operator_applications += in.operator_applications;
          ++stats.outer_iterations;
        }
      stats.time_solve = seconds_since(t1);
      stats.residual   = monitor.least_residual();
      return stats;
    }

    /// Appends the statistics of a later stage of solve_interior_point's chain to the chain's:
    /// the histories on the chain's clock (from the start of its first solve, after that solve's
    /// setup: a later stage's setup is part of the chain's solve), the iteration counts and W
    /// applications summed, the least residual, and the way the later stage ended. `stalls`
    /// gathers the stages' stall reasons; the chain's is theirs when its last stage stalled.
    void
    append_stage(ConeSolverStats &chain, const ConeSolverStats &stage, const std::string &name,
                 std::string &stalls)
    {
      const double start = chain.time_solve + stage.time_factorize;
      for (const double t : stage.time_history)
        chain.time_history.push_back(start + t);
      chain.residual_history.insert(chain.residual_history.end(), stage.residual_history.begin(),
                                    stage.residual_history.end());
      chain.time_solve += stage.time_factorize + stage.time_solve;
      chain.outer_iterations += stage.outer_iterations;
      chain.inner_iterations += stage.inner_iterations;
      chain.operator_applications += stage.operator_applications;
      if (stage.residual < chain.residual || std::isnan(chain.residual))
        chain.residual = stage.residual;
      chain.converged   = stage.converged;
      chain.interrupted = stage.interrupted;
      chain.timed_out   = stage.timed_out;
      chain.stalled     = stage.stalled;
      stalls += "; then " + name + ": " + stage.stall_reason;
      chain.stall_reason = stage.stalled ? stalls : std::string();
    }

    /// The interior point in the form InteriorPointTunables chooses, as a chain of stages each
    /// started only where the one before stalled, in the iterations and time left:
    /// 1. the split form (split_form = 1, the default; 0: the whole form alone, no stage 2);
    /// 2. the whole form from its own start (whole_form_after_stall);
    /// 3. Cadoux's fixed point with interior-point steps (4.4.2) from the best iterate so far
    ///    (fixed_point_after_stall).
    /// Stages 2 and 3 need mu > 0 and Bi = 0 (the whole form's scope; each fixed-point step is a
    /// whole-form solve). The iterate of least residual is returned; the statistics are the
    /// stages' together: outer_iterations counts the interior-point iterations of stages 1-2 and
    /// the fixed-point steps of stage 3, inner_iterations the interior-point iterations inside
    /// those steps, and max_outer_iterations bounds outer_iterations.
    ConeSolverStats
    solve_interior_point(const ConeProblemData &data, const ConeSolverOptions &options,
                         ConeSolution &solution)
    {
      const InteriorPointTunables &tune = options.interior_point;
      ConeSolverStats              stats;
      std::string                  stage = "split form";
      if (tune.split_form == 0.)
        {
          // The whole form factorises an augmented matrix that stays regular when A is singular,
          // and would end unconverged; one Cholesky factorisation of A refuses such an A first
          // (NotPositiveDefinite), as the split form's own factorisation of A does.
          const CholmodSolver definiteness_check(data.A);
          stats = solve_cone_problem_interior_point(data, options, solution);
          stage = "whole form";
        }
      else
        stats = solve_cone_problem_split_interior_point(data, options, solution);
      std::string stalls = stage + ": " + stats.stall_reason;
      // A later stage is started only if the time left would hold its setup and one iteration,
      // estimated by the first stage's (each factorises A or a matrix of its pattern first, then
      // one matrix per iteration); its own limit, which its solve measures from after its setup,
      // is what is left after that setup.
      const double setup = stats.time_factorize;
      const double iteration =
          stats.outer_iterations > 0 ? stats.time_solve / stats.outer_iterations : 0.;
      const auto used = [&] { return stats.time_factorize + stats.time_solve; };
      // The whole form handles mu > 0 and Bi = 0 only (a Bingham material has no other).
      const bool whole_applies =
          detail::interior_point_handles(data, detail::InteriorPointForm::whole);
      // Whether the stage `next` follows a stalled chain, and if it does not, why, in the log.
      const auto follows = [&](const double enabled, const std::string &next) {
        if (!stats.stalled || enabled == 0. ||
            stats.outer_iterations >= options.max_outer_iterations)
          return false;
        const bool no_time =
            options.max_seconds > 0. && used() + setup + iteration >= options.max_seconds;
        if (options.log && (!whole_applies || no_time))
          *options.log << "  the " << stage << " stalled at " << stats.residual << " ("
                       << stats.stall_reason << ") after " << used() << " s: "
                       << (whole_applies
                               ? "too little of the time limit is left for the " + next
                               : "the " + next + ", which needs mu > 0 and Bi = 0, does not apply")
                       << "\n";
        return whole_applies && !no_time;
      };
      // A later stage's options: the iterations and time left (its setup, if it has one, not
      // counted in its own limit).
      const auto later_options = [&](const double stage_setup) {
        ConeSolverOptions o    = options;
        o.max_outer_iterations = options.max_outer_iterations - stats.outer_iterations;
        if (options.max_seconds > 0.)
          o.max_seconds = options.max_seconds - used() - stage_setup;
        return o;
      };

      if (tune.split_form != 0. && follows(tune.whole_form_after_stall, "whole form"))
        {
          ConeSolverOptions whole_options         = later_options(setup);
          whole_options.interior_point.split_form = 0.;
          if (tune.whole_form_patience > 0. && std::isfinite(stats.residual))
            {
              whole_options.interior_point.beat_within = static_cast<unsigned int>(
                  std::ceil(tune.whole_form_patience * stats.outer_iterations));
              whole_options.interior_point.beat_residual = stats.residual;
            }
          // Progress counts on from the split form's iterations. Its last step, the one that
          // stalled, was not evaluated, so the whole form's starting point takes that number.
          const unsigned int before = stats.outer_iterations;
          if (options.progress)
            whole_options.progress = [&](const unsigned int k, const double residual) {
              options.progress(before + k, residual);
            };
          if (options.log)
            *options.log << "  the split form stalled at " << stats.residual << " ("
                         << stats.stall_reason << ") after " << stats.outer_iterations
                         << " iterations and " << used()
                         << " s: the whole form, from its own start (its table counts iterations "
                            "and time from there)\n";
          ConeSolution          whole_solution;
          const ConeSolverStats whole =
              solve_cone_problem_interior_point(data, whole_options, whole_solution);
          if (whole.residual < stats.residual || std::isnan(stats.residual))
            solution = std::move(whole_solution);
          append_stage(stats, whole, "whole form", stalls);
          stage = "whole form";
        }

      // (from a finite iterate only)
      if (std::isfinite(stats.residual) && follows(tune.fixed_point_after_stall, "fixed point"))
        {
          ConeSolverOptions fp_options = later_options(setup); // (it factorises A first)
          fp_options.method            = ConeMethod::fixed_point;
          fp_options.inner_solver      = InnerSolver::interior_point;
          // The fixed point records its start, the best iterate so far, first: that one is
          // numbered already, and each step's iterate takes the next number.
          const unsigned int before = stats.outer_iterations;
          if (options.progress)
            fp_options.progress = [&](const unsigned int k, const double residual) {
              if (k > 0)
                options.progress(before + k - 1, residual);
            };
          if (options.log)
            *options.log << "  the " << stage << " stalled at " << stats.residual << " ("
                         << stats.stall_reason << "), " << stats.outer_iterations
                         << " iterations and " << used()
                         << " s in all: Cadoux's fixed point with interior-point steps, from the "
                            "best iterate (its table counts steps and time from there)\n";
          // Its start, the best iterate's stress, with the velocity of the momentum balance: the
          // whole form's own velocity satisfies that balance only in the limit, so that start's
          // residual can be above the whole form's. The iterate of least residual is kept.
          ConeSolution          fp_solution = solution;
          const ConeSolverStats fp =
              data.block_size == 3
                  ? solve_fixed_point_interior_point<3>(data, fp_options, fp_solution)
                  : solve_fixed_point_interior_point<6>(data, fp_options, fp_solution);
          if (fp.residual < stats.residual)
            solution = std::move(fp_solution);
          append_stage(stats, fp, "fixed point", stalls);
          stats.fixed_point_steps = fp.outer_iterations;
        }
      return stats;
    }
  } // namespace

  HistoryHalves
  least_of_halves(const std::vector<double> &history)
  {
    // (std::min_element would stop at a NaN in first place)
    const auto least = [](const auto begin, const auto end) {
      double m = std::numeric_limits<double>::infinity();
      for (auto it = begin; it != end; ++it)
        if (*it < m)
          m = *it;
      return m;
    };
    const auto half = history.begin() + history.size() / 2;
    return {static_cast<std::size_t>(half - history.begin()),
            static_cast<std::size_t>(history.end() - half), least(history.begin(), half),
            least(half, history.end())};
  }

  ConeSolverStats
  solve_cone_problem(const ConeProblemData &data, const ConeSolverOptions &options,
                     ConeSolution &solution)
  {
    if (options.method == ConeMethod::interior_point)
      return solve_interior_point(data, options, solution);
    const bool ip_steps = options.inner_solver == InnerSolver::interior_point;
    if (data.block_size == 3)
      return ip_steps ? solve_fixed_point_interior_point<3>(data, options, solution)
                      : solve_blocks<3>(data, options, solution);
    if (data.block_size == 6)
      return ip_steps ? solve_fixed_point_interior_point<6>(data, options, solution)
                      : solve_blocks<6>(data, options, solution);
    throw std::invalid_argument("solve_cone_problem: block size must be 3 (2D) or 6 (3D)");
  }

  double
  cone_residual(const ConeProblemData &data, const ResidualKind kind, const Vector &lambda,
                const Vector &gamma)
  {
    if (data.block_size == 3)
      return ConeProduct<3>(data).residual(kind, lambda, gamma);
    if (data.block_size == 6)
      return ConeProduct<6>(data).residual(kind, lambda, gamma);
    throw std::invalid_argument("cone_residual: block size must be 3 (2D) or 6 (3D)");
  }

  InnerSolver
  parse_inner_solver(const std::string &name)
  {
    if (name == "pg")
      return InnerSolver::projected_gradient;
    if (name == "apgd")
      return InnerSolver::apgd;
    if (name == "spg")
      return InnerSolver::spg;
    if (name == "ip")
      return InnerSolver::interior_point;
    throw std::invalid_argument("unknown inner solver '" + name +
                                "': expected pg, apgd, spg or ip");
  }

  ConeMethod
  parse_cone_method(const std::string &name)
  {
    if (name == "fixed point")
      return ConeMethod::fixed_point;
    if (name == "interior point")
      return ConeMethod::interior_point;
    throw std::invalid_argument("unknown cone method '" + name +
                                "': expected fixed point or interior point");
  }

  std::string
  to_string(const InnerSolver s)
  {
    switch (s)
      {
        case InnerSolver::projected_gradient:
          return "pg";
        case InnerSolver::apgd:
          return "apgd";
        case InnerSolver::spg:
          return "spg";
        case InnerSolver::interior_point:
          return "ip";
      }
    return "?";
  }
} // namespace granflow::solvers
