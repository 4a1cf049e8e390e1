// Primal-dual interior-point method for the whole DP(mu, 0) problem (35), with De Saxce's term
// inside the Newton step. Daviet & Bertails-Descoubes 2016 solve (35) by Cadoux's fixed point on
// s = mu ||gamma_T|| (Algorithm 1), each step a convex SOCQP (37)/(39); on the mu = 0.5 silo of 6.4
// that fixed point is not a contraction. Here the unknowns are (u, lambda) and the complementarity
//   K_mu \ni lambda _|_ gamma_hat = gamma + mu ||gamma_T|| e_N \in K_{1/mu}        (Corollary 1)
// is followed along its central path, lambda o gamma_hat = tau e with tau -> 0 (Jordan product of
// the second-order cone). In the coordinates of K_1 (as for f_FB):
//   sl = D gamma_hat(u) in K_1,  z in K_1 with lambda = D z,  D = diag(1, mu, ..., mu),
//   A u - H^T D z = l                         (35a)
//   sl - D (gamma(u) + s(u) e_N) = 0,  gamma = H u + k,  s = mu ||gamma_T||
//   sl o z = tau e.
// Each iteration is a Mehrotra predictor-corrector step with Nesterov-Todd scaling W (W sl = W^-1
// z) (Nesterov & Todd 1997; Vandenberghe, "The CVXOPT linear and quadratic cone program solvers",
// 2010). The derivative of s(u) enters the Jacobian, which is therefore unsymmetric:
//   [ A        -H^T D ] [du]   [ l + H^T D z - A u        ]
//   [ -B H     -W^-2  ] [dz] = [ r_z - W^-1 c             ],   B = D (I + e_N sigma^T),
// sigma = (0, mu gamma_T / ||gamma_T||), r_z = D gamma_hat(u) - sl, and W dsl + W^-1 dz = c. With
// sigma = 0 the matrix is symmetric quasi-definite. By default (InteriorPointTunables::
// reduced_system) each step eliminates the stress, dz = -W^2 (r2 + B H du), and factorises the
// velocity block A + H^T D W^2 B H (UMFPACK), about half the cost of the augmented matrix on the
// silo's meshes. Near the solution W^2 spans many decades and that reduced solve loses accuracy
// (alone it stalls at 1.9e-6 on the 673-vertex silo), so it is refined on the augmented system
// until the componentwise backward error is below reduced_accuracy, and once refinement cannot
// get there the augmented matrix itself is factorised (diagonal pivots) for the rest of the solve.
// With s frozen at given values (solve_frozen_cone_problem_interior_point), sigma = 0 and the
// problem is the convex step (37) of Cadoux's fixed point, which cone_solver.cc iterates on.
#include "rheology/drucker_prager.h"
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
#include <sstream>
#include <stdexcept>
#include <utility>

namespace granflow::solvers
{
  namespace
  {
    using Vector = std::vector<double>;
    using Clock  = std::chrono::steady_clock;

    template <std::size_t n> class InteriorPoint
    {
      using S      = detail::Soc<n>;
      using Block  = typename S::Block;
      using Matrix = typename S::Matrix;

    public:
      InteriorPoint(const ConeProblemData &data, const ConeSolverOptions &options,
                    const std::vector<double> *frozen_s = nullptr)
          : data(data)
          , options(options)
          , frozen_s(frozen_s)
          , n_u(data.A.n_rows)
          , n_points(data.n_points())
          , m(n_points * n)
          , blocks(data)
          , lu(true)
      {
        detail::check_interior_point_scope(data, detail::InteriorPointForm::whole);
        build_pattern();
        if (reduced())
          {
            blocks.build_reduced_pattern();
            lu_reduced.set_refinement_steps(0); // refined on the augmented system instead
          }
      }

      ConeSolverStats
      solve(ConeSolution &solution)
      {
        const auto t0 = Clock::now();
        // The whole problem starts cold (interior points do not profit from a warm start there);
        // a frozen step of Cadoux's fixed point may start from the step before's solution.
        if (warm_start_applies(solution))
          warm_point(solution, u, sl, z);
        else
          initial_point(u, sl, z);
        if (options.log)
          *options.log << "  interior point (Mehrotra, Nesterov-Todd scaling)\n"
                       << "   iter      residual           gap       primal         dual      step"
                          "      time[s]\n";
        log_hand_over(0);
        return detail::run_interior_point(*this, options, solution, t0);
      }

      // The iterate's side of detail::run_interior_point.
      double
      residual()
      {
        evaluate(u, sl, z);
        if (!frozen_s)
          return cone_residual(data, options.residual, lambda_z, gamma_u);
        // The convex problem's Fischer-Burmeister residual, of lambda against gamma + s e_N: f_FB
        // adds mu ||gamma_T|| to gamma_N itself, so it is given gamma_N + s - mu ||gamma_T||.
        Vector g = gamma_u;
        for (std::size_t i = 0; i < n_points; ++i)
          g[i * n] += (*frozen_s)[i] - data.mu[i] * rheology::norm_T(block(gamma_u, i));
        return cone_residual(data, ResidualKind::fischer_burmeister, lambda_z, g);
      }

      void
      keep(ConeSolution &solution) const
      {
        solution.u      = u;
        solution.lambda = lambda_z;
        solution.gamma  = gamma_u;
      }

      void
      log_columns(std::ostream &log) const
      {
        log << std::setw(14) << gap << std::setw(13) << detail::norm_inf(r_z) << std::setw(13)
            << detail::norm_inf(r_x);
      }

      double
      newton_step()
      {
        return newton_step(u, sl, z);
      }

      void
      stepped(const unsigned int iteration)
      {
        log_hand_over(iteration);
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
      /// Once, the line saying that (and why) the augmented matrix has taken over, with the
      /// iteration whose step it happened in (0: the starting point); or, if the augmented matrix
      /// could not be factorised either, that the hand-over failed (the stall reason names why).
      void
      log_hand_over(const unsigned int iteration)
      {
        if (!options.log || hand_over_reason.empty() || hand_over_logged)
          return;
        *options.log << "  iteration " << iteration << ": the Newton systems go to the augmented "
                     << (factorization_failure.empty() ? "matrix from here on ("
                                                       : "matrix, which then failed too (")
                     << hand_over_reason << ")\n";
        hand_over_logged = true;
      }

      double
      D(const std::size_t k) const
      {
        return k % n == 0 ? 1. : data.mu[k / n];
      }

      /// Point i's block of x, whose points start at `offset`.
      Block
      block(const Vector &x, const std::size_t i, const std::size_t offset = 0) const
      {
        Block b;
        std::copy_n(x.begin() + offset + i * n, n, b.begin());
        return b;
      }

      static void
      set_block(Vector &x, const std::size_t i, const Block &b)
      {
        std::copy(b.begin(), b.end(), x.begin() + i * n);
      }

      /// The Newton matrix [A, -H^T D; -B H, -W^-2] in CSR. Its pattern is fixed: the rows of a
      /// constraint point all take the union of the columns of the point's rows of H.
      void
      build_pattern()
      {
        CsrMatrix Ht; // H^T, to fill the -H^T D block row by row
        Ht.n_rows = data.H.n_cols;
        Ht.n_cols = data.H.n_rows;
        Ht.row_start.assign(Ht.n_rows + 1, 0);
        for (const int c : data.H.column)
          ++Ht.row_start[c + 1];
        for (std::size_t r = 0; r < Ht.n_rows; ++r)
          Ht.row_start[r + 1] += Ht.row_start[r];
        Ht.column.resize(data.H.column.size());
        Ht.value.resize(data.H.column.size());
        std::vector<int> next(Ht.row_start.begin(), Ht.row_start.end() - 1);
        for (std::size_t r = 0; r < data.H.n_rows; ++r)
          for (int k = data.H.row_start[r]; k < data.H.row_start[r + 1]; ++k)
            {
              const int p  = next[data.H.column[k]]++;
              Ht.column[p] = static_cast<int>(r);
              Ht.value[p]  = data.H.value[k];
            }

        K.n_rows = K.n_cols = n_u + m;
        K.row_start.assign(1, 0);
        for (std::size_t r = 0; r < n_u; ++r)
          {
            for (int k = data.A.row_start[r]; k < data.A.row_start[r + 1]; ++k)
              {
                K.column.push_back(data.A.column[k]);
                K.value.push_back(data.A.value[k]);
              }
            for (int k = Ht.row_start[r]; k < Ht.row_start[r + 1]; ++k)
              {
                K.column.push_back(static_cast<int>(n_u) + Ht.column[k]);
                K.value.push_back(-D(Ht.column[k]) * Ht.value[k]);
              }
            K.row_start.push_back(static_cast<int>(K.column.size()));
          }
        for (std::size_t i = 0; i < n_points; ++i)
          for (std::size_t a = 0; a < n; ++a)
            {
              for (const int c : blocks.columns(i))
                K.column.push_back(c);
              for (std::size_t b = 0; b < n; ++b)
                K.column.push_back(static_cast<int>(n_u + i * n + b));
              K.row_start.push_back(static_cast<int>(K.column.size()));
            }
        K.value.resize(K.column.size(), 0.);
      }

      /// Fills the constraint rows of K: -B_i H_i (B = D (I + e_N sigma^T)) and -W_i^-2.
      void
      fill_constraint_rows(const std::vector<Block> &sigma, const std::vector<Matrix> &W_inv2)
      {
        for (std::size_t i = 0; i < n_points; ++i)
          {
            const std::size_t nc = blocks.columns(i).size();
            const double     *Hi = blocks.H(i);
            for (std::size_t a = 0; a < n; ++a)
              {
                double *row = &K.value[K.row_start[n_u + i * n + a]];
                for (std::size_t c = 0; c < nc; ++c)
                  {
                    double v;
                    if (a == 0)
                      {
                        v = Hi[c];
                        for (std::size_t b = 1; b < n; ++b)
                          v += sigma[i][b] * Hi[b * nc + c];
                      }
                    else
                      v = data.mu[i] * Hi[a * nc + c];
                    row[c] = -v;
                  }
                for (std::size_t b = 0; b < n; ++b)
                  row[nc + b] = -W_inv2[i][a][b];
              }
          }
      }

      bool
      reduced() const
      {
        return options.interior_point.reduced_system != 0.;
      }

      /// M_i = D W_i^2 B_i, B_i = D (I + e_N sigma_i^T): the point's block of the reduced matrix
      /// between H_i^T and H_i.
      Matrix
      reduced_block(const std::size_t i, const Block &sigma, const Matrix &W2) const
      {
        Matrix M{};
        for (std::size_t a = 0; a < n; ++a)
          {
            const double Da = D(i * n + a);
            for (std::size_t b = 0; b < n; ++b)
              { // (D W2 B)_ab = D_a (W2_a0 B_0b + W2_ab mu) with B_0b = delta_0b + sigma_b
                double v = W2[a][0] * ((b == 0 ? 1. : 0.) + sigma[b]);
                if (b > 0)
                  v += W2[a][b] * data.mu[i];
                M[a][b] = Da * v;
              }
          }
        return M;
      }

      /// Factorises the Newton matrix: K (augmented, whose constraint rows the caller has filled)
      /// or R (reduced, from sigma and W^2 = `W2`).
      void
      factorize(const std::vector<Block> &sigma, std::vector<Matrix> W2)
      {
        if (!reduced() || augmented_from_now)
          {
            factorize_augmented();
            return;
          }
        reduced_W2    = std::move(W2);
        reduced_sigma = sigma;
        std::vector<Matrix> M(n_points);
        for (std::size_t i = 0; i < n_points; ++i)
          M[i] = reduced_block(i, sigma[i], reduced_W2[i]);
        try
          {
            lu_reduced.factorize(blocks.reduced(M));
            ++factorizations;
          }
        catch (const std::runtime_error &e)
          {
            // K may well factorise where R does not
            hand_over(std::string("the reduced matrix could not be factorised (") + e.what() + ")");
          }
      }

      /// From now on the augmented matrix K (whose constraint rows the caller has filled) is
      /// factorised, and the reduced factorisation is freed. `reason` goes to the log.
      void
      hand_over(const std::string &reason)
      {
        hand_over_reason   = "in the " + std::string(phase) + ", " + reason;
        augmented_from_now = true;
        lu_reduced.release();
        factorize_augmented();
      }

      void
      factorize_augmented()
      {
        lu.factorize(K);
        ++factorizations;
      }

      /// x = K^-1 rhs. Reduced: the constraint rows -B H du - W^-2 dz = r2 give
      /// dz = -W^2 (r2 + B H du), and R du = r1 - H^T D W^2 r2; then `refinement_steps` steps of
      /// iterative refinement on K itself, whose residual the elimination does not control.
      void
      linear_solve(Vector &x, const Vector &rhs)
      {
        if (!reduced() || augmented_from_now)
          {
            lu.solve(x, rhs);
            return;
          }
        const auto eliminate = [&](Vector &y, const Vector &b) {
          Vector t(m), Ht, r1(b.begin(), b.begin() + n_u), du, Hdu;
          for (std::size_t i = 0; i < n_points; ++i)
            {
              const Block w = S::apply(reduced_W2[i], block(b, i, n_u));
              for (std::size_t a = 0; a < n; ++a)
                t[i * n + a] = D(i * n + a) * w[a];
            }
          data.H.Tvmult(Ht, t);
          for (std::size_t k = 0; k < n_u; ++k)
            r1[k] -= Ht[k];
          lu_reduced.solve(du, r1);
          data.H.vmult(Hdu, du);
          y.assign(n_u + m, 0.);
          std::copy(du.begin(), du.end(), y.begin());
          for (std::size_t i = 0; i < n_points; ++i)
            {
              Block       v = block(b, i, n_u);
              const Block h = block(Hdu, i);
              v[0] += h[0];
              for (std::size_t a = 1; a < n; ++a)
                {
                  v[0] += reduced_sigma[i][a] * h[a];
                  v[a] += data.mu[i] * h[a];
                }
              const Block w = S::apply(reduced_W2[i], v);
              for (std::size_t a = 0; a < n; ++a)
                y[n_u + i * n + a] = -w[a];
            }
        };
        eliminate(x, rhs);
        Vector correction, residual(n_u + m);
        double backward_error = 0.;
        for (unsigned int step = 0;; ++step)
          {
            // The residual rhs - K x and the componentwise backward error (Oettli-Prager)
            // |r_k| / (|K| |x| + |rhs|)_k, in one pass over K (a row whose scale is 0 has a
            // residual of exactly 0); a non-finite x fails.
            double relative = 0.;
            for (std::size_t r = 0; r < n_u + m; ++r)
              {
                double Kx = 0., scale = std::abs(rhs[r]);
                for (int k = K.row_start[r]; k < K.row_start[r + 1]; ++k)
                  {
                    const double term = K.value[k] * x[K.column[k]];
                    Kx += term;
                    scale += std::abs(term);
                  }
                residual[r]        = rhs[r] - Kx;
                const double ratio = scale > 0. ? std::abs(residual[r]) / scale : residual[r];
                relative           = std::isfinite(ratio) && std::isfinite(scale)
                                         ? std::max(relative, std::abs(ratio))
                                         : std::numeric_limits<double>::infinity();
              }
            backward_error = relative;
            if (relative <= options.interior_point.reduced_accuracy)
              return;
            if (step == options.interior_point.refinement_steps)
              break;
            eliminate(correction, residual);
            for (std::size_t k = 0; k < n_u + m; ++k)
              x[k] += correction[k];
          }
        // The reduced system has lost the accuracy the step needs: the augmented one from now on.
        std::ostringstream reason;
        if (std::isfinite(backward_error))
          reason << "the reduced solve's backward error was " << detail::as_written(backward_error)
                 << " after " << options.interior_point.refinement_steps
                 << " refinement steps (reduced_accuracy "
                 << detail::as_written(options.interior_point.reduced_accuracy) << ")";
        else
          reason << "the reduced solve was not finite";
        hand_over(reason.str());
        lu.solve(x, rhs);
      }

      /// gamma(u) = H u + k, s(u), the stress lambda = D z, the residuals r_x = l + H^T lambda - A
      /// u and r_z = D (gamma + s e_N) - sl, and the duality gap sl . z.
      void
      evaluate(const Vector &u, const Vector &sl, const Vector &z)
      {
        data.H.vmult(gamma_u, u);
        for (std::size_t k = 0; k < m; ++k)
          gamma_u[k] += data.k[k];
        r_z.resize(m);
        for (std::size_t i = 0; i < n_points; ++i)
          {
            const Block  g = block(gamma_u, i);
            const double s = frozen_s ? (*frozen_s)[i] : data.mu[i] * rheology::norm_T(g);
            for (std::size_t a = 0; a < n; ++a)
              r_z[i * n + a] = (a == 0 ? g[0] + s : data.mu[i] * g[a]) - sl[i * n + a];
          }
        lambda_z.resize(m);
        for (std::size_t k = 0; k < m; ++k)
          lambda_z[k] = D(k) * z[k];
        Vector Au;
        data.H.Tvmult(r_x, lambda_z);
        data.A.vmult(Au, u);
        for (std::size_t k = 0; k < n_u; ++k)
          r_x[k] += data.l[k] - Au[k];
        gap = 0.;
        for (std::size_t k = 0; k < m; ++k)
          gap += sl[k] * z[k];
      }

      /// Pushes point i's block of x into the interior of K_1: x_0 += max(0, ||x_bar|| - x_0) +
      /// margin.
      void
      push_interior(Vector &x, const std::size_t i, const double margin) const
      {
        Block b = block(x, i);
        b[0] += std::max(0., rheology::norm_T(b) - b[0]) + margin;
        set_block(x, i, b);
      }

      /// Pushes each block of x into the interior of K_1 by `margin`.
      void
      make_interior(Vector &x, const double margin) const
      {
        for (std::size_t i = 0; i < n_points; ++i)
          push_interior(x, i, margin);
      }

      /// Starting point as in CVXOPT's coneqp: the least-squares solution with W = I, i.e.
      /// (A + H^T D^2 H) u = l - H^T D^2 k, then sl = D gamma_hat(u) and z = -sl, each pushed
      /// into the interior of K_1.
      void
      initial_point(Vector &u, Vector &sl, Vector &z)
      {
        std::vector<Block>  sigma(n_points, Block{});
        std::vector<Matrix> identity(n_points, Matrix{});
        for (auto &I : identity)
          for (std::size_t a = 0; a < n; ++a)
            I[a][a] = 1.;
        fill_constraint_rows(sigma, identity);
        // sigma = 0 and B = D: the second block row reads -D H u - v = D k.
        Vector rhs(n_u + m, 0.), x;
        std::copy(data.l.begin(), data.l.end(), rhs.begin());
        for (std::size_t k = 0; k < m; ++k)
          rhs[n_u + k] = D(k) * data.k[k];
        phase = "starting point";
        factorize(sigma, std::move(identity)); // W^2 = I, no longer needed here
        linear_solve(x, rhs);
        u.assign(x.begin(), x.begin() + n_u);
        evaluate(u, Vector(m, 0.), Vector(m, 0.)); // r_z = D gamma_hat(u)
        sl = r_z;
        z  = r_z;
        for (double &v : z)
          v = -v;
        const double margin = options.interior_point.initial_margin;
        make_interior(sl, margin);
        make_interior(z, margin * std::max(1., detail::norm_inf(z)));
      }

      /// Whether `solution` is a warm start to take (InteriorPointTunables::warm_start_shift):
      /// a frozen step only, with a velocity and a stress of the problem's sizes.
      bool
      warm_start_applies(const ConeSolution &solution) const
      {
        return frozen_s && options.interior_point.warm_start_shift > 0. &&
               solution.u.size() == n_u && solution.lambda.size() == m;
      }

      /// The warm start of a frozen step: the given velocity and stress, sl = D (gamma(u) + s e_N)
      /// and z = D^-1 lambda, each pushed into the interior of K_1 by theta = warm_start_shift
      /// times the step's tolerance, in the residual's units (lambda against gamma_scale_i gamma:
      /// sl's block by theta / gamma_scale_i). So the gap starts at about the level the step is
      /// to end below, not at the cold start's, and the step's solution, close to the previous
      /// one's when s has changed little, is a few Newton steps away.
      void
      warm_point(const ConeSolution &solution, Vector &u, Vector &sl, Vector &z)
      {
        u = solution.u;
        evaluate(u, Vector(m, 0.), Vector(m, 0.)); // r_z = D gamma_hat(u)
        sl = r_z;
        z.resize(m);
        for (std::size_t k = 0; k < m; ++k)
          z[k] = solution.lambda[k] / D(k);
        const double theta = options.interior_point.warm_start_shift * options.tolerance;
        for (std::size_t i = 0; i < n_points; ++i)
          {
            push_interior(sl, i, theta / (data.gamma_scale.empty() ? 1. : data.gamma_scale[i]));
            push_interior(z, i, theta);
          }
      }

      /// Largest step in [0, 1] along (dsl, dz) that keeps every block interior.
      double
      max_step(const Vector &sl, const Vector &dsl, const Vector &z, const Vector &dz) const
      {
        double t = 1.;
        for (std::size_t i = 0; i < n_points; ++i)
          t = std::min({t, S::max_step(block(sl, i), block(dsl, i)),
                        S::max_step(block(z, i), block(dz, i))});
        return t;
      }

      /// One Mehrotra predictor-corrector step; returns the step length taken (0: none).
      double
      newton_step(Vector &u, Vector &sl, Vector &z)
      {
        // evaluate() was called at (u, sl, z): gamma_u, r_x, r_z, gap are current.
        std::vector<Block>  sigma(n_points), lambda(n_points);
        std::vector<Matrix> W(n_points), W_inv(n_points), W_inv2(n_points);
        for (std::size_t i = 0; i < n_points; ++i)
          {
            const Block  g  = block(gamma_u, i);
            const double gt = rheology::norm_T(g);
            sigma[i]        = Block{};
            if (!frozen_s) // a frozen s does not move with u
              for (std::size_t b = 1; b < n; ++b)
                sigma[i][b] = gt > 0. ? data.mu[i] * g[b] / gt : 0.; // a subgradient at gamma_T = 0
            S::nesterov_todd(block(sl, i), block(z, i), W[i], W_inv[i]);
            W_inv2[i] = S::multiply(W_inv[i], W_inv[i]);
            lambda[i] = S::apply(W[i], block(sl, i));
          }
        fill_constraint_rows(sigma, W_inv2);
        phase = "factorisation";
        try
          {
            std::vector<Matrix> W2;
            if (reduced() && !augmented_from_now)
              for (std::size_t i = 0; i < n_points; ++i)
                W2.push_back(S::multiply(W[i], W[i]));
            factorize(sigma, std::move(W2));
          }
        catch (const std::runtime_error &e)
          {
            factorization_failure = e.what(); // named in the stall reason
            return 0.;
          }

        Vector du, dsl(m), dz(m), rhs(n_u + m), x;
        // Solves for the complementarity right-hand side rc: W dsl + W^-1 dz = lambda \ rc.
        // False if the augmented matrix, factorised when the reduced solve hands over, could not
        // be.
        const auto direction = [&](const std::vector<Block> &rc) {
          std::copy(r_x.begin(), r_x.end(), rhs.begin());
          std::vector<Block> W_inv_c(n_points); // W^-1 c with c = lambda \ rc
          for (std::size_t i = 0; i < n_points; ++i)
            {
              W_inv_c[i] = S::apply(W_inv[i], S::arrow_solve(lambda[i], rc[i]));
              for (std::size_t a = 0; a < n; ++a)
                rhs[n_u + i * n + a] = r_z[i * n + a] - W_inv_c[i][a];
            }
          try
            {
              linear_solve(x, rhs);
            }
          catch (const std::runtime_error &e)
            {
              factorization_failure = e.what(); // named in the stall reason
              return false;
            }
          du.assign(x.begin(), x.begin() + n_u);
          std::copy(x.begin() + n_u, x.end(), dz.begin());
          // dsl = W^-1 c - W^-2 dz
          for (std::size_t i = 0; i < n_points; ++i)
            {
              const Block w = S::apply(W_inv2[i], block(dz, i));
              for (std::size_t a = 0; a < n; ++a)
                dsl[i * n + a] = W_inv_c[i][a] - w[a];
            }
          return true;
        };

        const double       tau = gap / static_cast<double>(n_points);
        std::vector<Block> rc(n_points);
        for (std::size_t i = 0; i < n_points; ++i) // predictor: rc = -lambda o lambda
          {
            rc[i] = S::product(lambda[i], lambda[i]);
            for (double &v : rc[i])
              v = -v;
          }
        phase = "predictor";
        if (!direction(rc))
          return 0.;
        const double t_affine   = max_step(sl, dsl, z, dz);
        double       gap_affine = 0.;
        for (std::size_t k = 0; k < m; ++k)
          gap_affine += (sl[k] + t_affine * dsl[k]) * (z[k] + t_affine * dz[k]);
        const double centering = std::pow(std::clamp(gap_affine / gap, 0., 1.),
                                          options.interior_point.centering_exponent);
        for (std::size_t i = 0; i < n_points; ++i) // corrector
          {
            const Block ds = S::apply(W[i], block(dsl, i)), dzs = S::apply(W_inv[i], block(dz, i));
            const Block second = S::product(ds, dzs);
            for (std::size_t a = 0; a < n; ++a)
              rc[i][a] -= second[a];
            rc[i][0] += centering * tau;
          }
        phase = "corrector";
        if (!direction(rc))
          return 0.;
        double t = std::min(1., options.interior_point.step_fraction * max_step(sl, dsl, z, dz));
        // Rounding can still put a block on the boundary: halve until every block is interior.
        const auto interior = [&](const double t) {
          for (std::size_t i = 0; i < n_points; ++i)
            {
              Block a = block(sl, i), b = block(z, i);
              for (std::size_t j = 0; j < n; ++j)
                {
                  a[j] += t * dsl[i * n + j];
                  b[j] += t * dz[i * n + j];
                }
              if (!S::interior(a) || !S::interior(b))
                return false;
            }
          return true;
        };
        t           = detail::halve_until_interior(t, interior);
        bool finite = true;
        for (const double v : x)
          finite = finite && std::isfinite(v);
        if (t == 0. || !finite)
          return 0.;
        for (std::size_t k = 0; k < n_u; ++k)
          u[k] += t * du[k];
        for (std::size_t k = 0; k < m; ++k)
          {
            sl[k] += t * dsl[k];
            z[k] += t * dz[k];
          }
        return t;
      }

      const ConeProblemData           &data;
      const ConeSolverOptions         &options;
      const std::vector<double>       *frozen_s; // null: De Saxce's s(u) = mu ||gamma_T(u)||
      const std::size_t                n_u, n_points, m;
      detail::PointBlocks              blocks;
      CsrMatrix                        K;
      UmfpackSolver                    lu;
      // The reduced system (InteriorPointTunables::reduced_system): R's factorisation (R itself is
      // in `blocks`), and the W^2 and sigma it was built from.
      UmfpackSolver                    lu_reduced{true};
      std::vector<Matrix>              reduced_W2;
      std::vector<Block>               reduced_sigma;
      bool                             augmented_from_now = false;
      const char                      *phase = "starting point"; // the solve in progress
      std::string                      hand_over_reason;         // why, once it has happened
      bool                             hand_over_logged = false;
      unsigned int                     factorizations = 0;
      std::string                      factorization_failure; // UMFPACK's message, if it failed
      Vector                           u, sl, z;              // the iterate
      Vector                           gamma_u, lambda_z, r_x, r_z; // set by evaluate()
      double                           gap = 0.;
    };
  } // namespace

  ConeSolverStats
  solve_cone_problem_interior_point(const ConeProblemData &data, const ConeSolverOptions &options,
                                    ConeSolution &solution)
  {
    return detail::construct_and_solve<InteriorPoint>(data, options, solution);
  }

  ConeSolverStats
  solve_frozen_cone_problem_interior_point(const ConeProblemData     &data,
                                           const std::vector<double> &s,
                                           const ConeSolverOptions &options, ConeSolution &solution)
  {
    return detail::construct_and_solve<InteriorPoint>(data, options, solution, &s);
  }
} // namespace granflow::solvers
