// The discrete DP(mu, Bi) problem of Daviet & Bertails-Descoubes 2016, (35)-(36), as plain data:
//   A u = H^T lambda + l,   gamma = H u + k,   f_DS(lambda_i, gamma_i) = 0 at every constraint
//   point i,
// with H = R^{+T} B and k = R^{+T} k_D. Eliminating u gives the SOCCP (36):
//   gamma = W lambda + w,  W = H A^{-1} H^T,  w = H A^{-1} l + k.
// Data / Options / Stats follow So-bogus: the solver takes the three structs, tunables have their
// defaults here, and a problem can be dumped to a file and replayed by bench/replay_cone_problem.
#pragma once

#include "solvers/sparse.h"

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace granflow::solvers
{
  struct ConeProblemData
  {
    unsigned int        block_size = 3; // s(d): 3 in 2D, 6 in 3D
    CsrMatrix           A;              // SPD velocity operator on the free dofs (25a)
    CsrMatrix           H;              // n_points * block_size rows: gamma = H u + k
    std::vector<double> l;              // load on the free dofs, Dirichlet lifting subtracted
    std::vector<double> k;              // H applied to the Dirichlet lifting
    std::vector<double> mu;             // friction coefficient per constraint point
    std::vector<double> Bi;             // Bingham number per constraint point
    /// Per point, > 0 (empty: all 1): the residual compares lambda_i with gamma_scale_i gamma_i,
    /// so that a tolerance means the same at every point. gamma_i carries the point's weight
    /// (Property 3); the dp model divides it out and turns the strain rate into the viscous stress
    /// it drives, eta_i / (Re w_i) (eta_i the point's viscosity: 1, or |D| for Bagnold's). The
    /// solution does not depend on it.
    std::vector<double> gamma_scale;

    std::size_t
    n_points() const
    {
      return mu.size();
    }
  };

  enum class InnerSolver
  {
    projected_gradient, // PG with backtracking line search (Algorithm 2 + line search)
    apgd,               // Nesterov's accelerated projected gradient with restart (Heyn 2013)
    spg,                // spectral projected gradient, Barzilai-Borwein steps (Tasora 2013)
    interior_point      // the whole-form interior point on each convex step (4.4.2), mu > 0, Bi = 0
  };

  enum class ConeMethod
  {
    fixed_point,   // Cadoux's fixed point on s (Algorithm 1) with an inner SOCQP solver
    interior_point // primal-dual interior point: the split form (mu > 0 or Bi > 0), then the whole
                   // problem where that stalls (mu > 0, Bi = 0 only)
  };

  enum class ResidualKind
  {
    alart_curnier,     // Definition 2, valid for any Bi
    fischer_burmeister // SOC FB (Daviet et al. 2011), Bi = 0 only
  };

  /// Tunables of Cadoux's fixed point and its inner solvers. The defaults are the values the
  /// measurements of docs/solvers.md were made with (but for the stagnation rule, which came after
  /// most of them, in session 35); a case file does not set them.
  struct FixedPointTunables
  {
    /// An outer iteration stalls when its residual is above stall_ratio times the least before it.
    /// A stall drops the Anderson history; stalls_before_tightening successive stalls raise the
    /// inner iteration cap (if the last inner solve hit it; up to max_inner_growth times
    /// ConeSolverOptions::max_inner_iterations) or tighten the inner tolerance factor (down to
    /// min_inner_tolerance_factor).
    double       stall_ratio                = 0.9;
    unsigned int stalls_before_tightening   = 2;
    unsigned int max_inner_growth           = 64;
    double       min_inner_tolerance_factor = 1e-4;
    /// The inner tolerance never goes below this fraction of ConeSolverOptions::tolerance.
    double inner_tolerance_floor = 1e-3;
    /// The fixed point (any inner solver) ends as stalled once it has recorded at least
    /// stagnation_min_iterations residuals and the least of the later half of them is above
    /// stagnation_ratio times the least of the earlier half: such a run had oscillated or crawled
    /// for the rest of its iteration limit (the Bagnold layer at tan alpha = 0.7 between 2.5e-5
    /// and 5e-5 for 450 iterations; docs/solvers.md). 0 never ends it so.
    unsigned int stagnation_min_iterations = 20;
    double       stagnation_ratio          = 0.5;
    /// Tikhonov regularisation of Anderson's least-squares normal equations (relative).
    double anderson_regularization = 1e-10;
    /// ||W|| is estimated by this many power iterations, times norm_margin (an upper estimate
    /// is what the projected-gradient step 1/L needs).
    unsigned int norm_estimate_iterations = 20;
    double       norm_margin              = 1.1;
    /// APGD: the first Lipschitz estimate is at least this fraction of ||W||'s estimate; after
    /// each iteration the estimate shrinks by lipschitz_decrease (it doubles on backtracking).
    double apgd_min_lipschitz_fraction = 1e-3;
    double apgd_lipschitz_decrease     = 0.9;
    /// SPG: nonmonotone Armijo search over the last spg_memory objective values, with the
    /// sufficient-decrease constant spg_armijo; Barzilai-Borwein steps in [1, spg_max_step] times
    /// 1/||W|| (relative: ||W|| scales with Re; 1e7 / ||W|| is about the former absolute 1e10 at
    /// Re = 1 on the Bingham Poiseuille mesh, ||W|| = 2.9e-4 there).
    unsigned int spg_memory   = 10;
    double       spg_armijo   = 1e-4;
    double       spg_max_step = 1e7;
  };

  /// Tunables of the interior point (cone_interior_point.cc), defaults as measured in
  /// docs/solvers.md.
  struct InteriorPointTunables
  {
    /// 1 (the default): the interior point on the split form of the law
    /// (cone_split_interior_point.cc), whose central path is bilinear; 0: on the whole
    /// complementarity of Corollary 1, De Saxce's term linearised in each step
    /// (cone_interior_point.cc). The split form uses step_fraction, centering_exponent and the
    /// stall rules; the other tunables are the whole form's. Neither form is better on every
    /// problem measured (docs/solvers.md, session 24), so with whole_form_after_stall = 1 a split
    /// solve that stalls is followed by a whole one from its own start, in the time left. With
    /// fixed_point_after_stall = 1, where that stalls too (or the one form run stalls), Cadoux's
    /// fixed point with interior-point steps (4.4.2) follows, started from the best iterate so
    /// far: from there it converged on the 2591-vertex silo where both forms stall, and it
    /// lowered the residual of every stalled run of docs/dp.md 4 to 40 times (sessions 42-43,
    /// docs/solvers.md). The iterate of least residual is returned; the iteration limit
    /// (max_outer_iterations) covers all stages, the fixed point's steps counted as its
    /// iterations.
    double split_form              = 1.;
    double whole_form_after_stall  = 1.;
    double fixed_point_after_stall = 1.;
    /// Fraction of the longest step that keeps every block interior.
    double step_fraction = 0.99;
    /// Mehrotra's centring: sigma = (gap after the affine step / gap)^centering_exponent.
    double centering_exponent = 3.;
    /// The starting point is pushed this far (relative) into the interior of K_1.
    double initial_margin = 1e-3;
    /// > 0: each frozen step of Cadoux's fixed point with interior-point steps
    /// (solve_frozen_cone_problem_interior_point) starts from the solution it is given, the step
    /// before's, pushed into the interior of K_1 by warm_start_shift times the step's tolerance;
    /// 0: from its own (cold) start, as the whole problem always does. The default, 10, is the
    /// shift measured on the four silos of Table 2 (docs/solvers.md).
    double warm_start_shift = 10.;
    /// Stall rules, each ending the solve with its best iterate: `short_steps` successive steps
    /// shorter than `short_step`, or `stagnation_iterations` iterations without reducing the
    /// least residual below `stagnation_ratio` times its value at the last such reduction.
    double       short_step            = 1e-4;
    unsigned int short_steps           = 5;
    unsigned int stagnation_iterations = 50;
    double       stagnation_ratio      = 0.9;
    /// The whole form after a stalled split form (whole_form_after_stall) also stalls once it has
    /// taken whole_form_patience times the split form's iterations without its least residual
    /// going below the split form's. Where it gained on the problems measured, it went below
    /// within about as many iterations as the split form took; on the 40265-vertex silo it never
    /// did, in 86 iterations and 478 s (docs/solvers.md, session 43). 0: no such limit.
    double whole_form_patience = 1.5;
    /// Set by solve_cone_problem for the whole form from whole_form_patience, not by hand: with
    /// beat_within > 0, the solve stalls after beat_within iterations if its least residual is not
    /// below beat_residual.
    unsigned int beat_within   = 0;
    double       beat_residual = 0.;
    /// 1: each Newton system is solved through its velocity block A + H^T D W^2 B H, the stress
    /// eliminated, then refined on the augmented system [A, -H^T D; -B H, -W^-2] (at most
    /// `refinement_steps` steps) until its componentwise backward error is at most
    /// `reduced_accuracy`; where that fails, the augmented matrix is factorised instead, for that
    /// solve and every later one. 0: the augmented matrix throughout. (docs/solvers.md)
    double       reduced_system   = 1.;
    unsigned int refinement_steps = 3;
    double       reduced_accuracy = 1e-14;
  };

  struct ConeSolverOptions
  {
    ConeMethod   method       = ConeMethod::fixed_point;
    InnerSolver  inner_solver = InnerSolver::spg; // fixed point only
    ResidualKind residual     = ResidualKind::fischer_burmeister; // AC is used where Bi > 0
    double       tolerance    = 1e-6;  // infinity norm of the residual over the constraint points
    unsigned int max_outer_iterations = 200; // fixed-point or interior-point iterations
    unsigned int max_inner_iterations =
        300; // per fixed-point iteration: the outer loop goes on from the warm start
    /// The inner SOCQP (37) is solved to inner_tolerance_factor times the current outer residual
    /// (never below tolerance / 1000): early fixed-point iterations need no accurate inner solve.
    double        inner_tolerance_factor = 0.1;
    /// Anderson acceleration of the fixed point on s (0: plain Algorithm 1).
    unsigned int  anderson_depth = 5;
    double        max_seconds            = 0.;      // wall-time limit of the solve, 0: none
    std::ostream *log                    = nullptr; // fixed-column iteration table, if set
    /// Called after every fixed-point iteration with (iteration, residual): console progress.
    std::function<void(unsigned int, double)> progress;
    /// Polled by the outer and the inner iterations: once it returns true, the solve ends as at
    /// the time limit, with the iterate of least residual and stats.interrupted set.
    std::function<bool()> stop_requested;
    FixedPointTunables    fixed_point;
    InteriorPointTunables interior_point;
  };

  struct ConeSolverStats
  {
    bool         converged            = false;
    bool         interrupted           = false; // ended by options.stop_requested
    bool         stalled               = false; // ended by the method's stagnation rules
    std::string  stall_reason;                  // which of them, in words
    bool         timed_out             = false; // ended by options.max_seconds
    unsigned int outer_iterations     = 0;
    unsigned int inner_iterations     = 0; // summed over the outer iterations
    /// Interior point: the steps of its fixed-point stage (InteriorPointTunables::
    /// fixed_point_after_stall), counted in outer_iterations; the interior-point iterations
    /// inside them are inner_iterations.
    unsigned int fixed_point_steps     = 0;
    unsigned int operator_applications = 0; // applications of W (one A^{-1} back-solve each);
                                            // interior point: factorisations of its Newton matrix
    double       residual             = 0.;
    double       time_factorize       = 0.; // seconds
    double       time_solve           = 0.; // seconds
    std::vector<double> residual_history; // per outer iteration
    std::vector<double> time_history;     // wall time since the solve began, per outer iteration
  };

  /// Solution, also the warm start: lambda (and u) on entry are the initial guess.
  struct ConeSolution
  {
    std::vector<double> u;      // free velocity dofs
    std::vector<double> lambda; // stress at the constraint points, chi-coordinates
    std::vector<double> gamma;  // scaled strain rate at the constraint points, chi-coordinates
  };

  /// Cadoux's fixed point (Algorithm 1, Section 4.4.1; Bi > 0 through the truncated cone, 4.5.2)
  /// with the inner SOCQP min_{lambda in K} 1/2 lambda^T W lambda + lambda^T (w + (s; 0))
  /// (37)/(43). A is factorised once; W is applied without being assembled.
  ConeSolverStats
  solve_cone_problem(const ConeProblemData &data, const ConeSolverOptions &options,
                     ConeSolution &solution);

  /// The whole problem (35) by a primal-dual interior-point method (cone_interior_point.cc): the
  /// complementarity of Corollary 1 followed along its central path, De Saxce's term mu ||gamma_T||
  /// linearised inside each Newton step. Requires mu > 0 and Bi = 0 at every point (throws
  /// std::invalid_argument otherwise). Called by solve_cone_problem for ConeMethod::interior_point
  /// with InteriorPointTunables::split_form = 0.
  ConeSolverStats
  solve_cone_problem_interior_point(const ConeProblemData &data, const ConeSolverOptions &options,
                                    ConeSolution            &solution);

  /// The convex SOCQP (37)/(39) of one step of Cadoux's fixed point, De Saxce's term frozen at
  /// s (one value per point): K_mu \ni lambda _|_ gamma + s e_N \in K_{1/mu}, by the whole-form
  /// interior point with that s (its Newton matrix then symmetric quasi-definite). The residual
  /// it stops on is this problem's Fischer-Burmeister residual; `solution.gamma` is H u + k.
  ConeSolverStats
  solve_frozen_cone_problem_interior_point(const ConeProblemData     &data,
                                           const std::vector<double> &s,
                                           const ConeSolverOptions   &options,
                                           ConeSolution              &solution);

  /// The same problem by an interior point on the split form of the law (see
  /// InteriorPointTunables::split_form and cone_split_interior_point.cc), alone; same
  /// requirements. solve_cone_problem follows it with the whole form where it stalls.
  ConeSolverStats
  solve_cone_problem_split_interior_point(const ConeProblemData   &data,
                                          const ConeSolverOptions &options, ConeSolution &solution);

  namespace detail
  {
    /// An iterate of the split form (cone_split_interior_point.cc): the velocity u, the stress
    /// lambda, and per point the slack a of gamma_N and x = (t, x_T), x_T the slack of gamma_T.
    struct SplitIterate
    {
      std::vector<double> u, lambda, a, x;
    };

    struct SplitDirection
    {
      std::vector<double> du, da, dlambda, dx;
    };

    /// The split form's Newton direction at `iterate`, as its solver computes it, for the
    /// complementarity right-hand sides rc1 (one per point) and rc2 (block_size per point): for
    /// tests against a direct solve of the whole linearised system.
    SplitDirection
    split_form_direction(const ConeProblemData &data, const SplitIterate &iterate,
                         const std::vector<double> &rc1, const std::vector<double> &rc2);
  } // namespace detail

  /// Residual of DP(mu, Bi) at every point (lambda_i against gamma_scale_i gamma_i), infinity norm
  /// over the points of the Euclidean norms.
  double
  cone_residual(const ConeProblemData &data, ResidualKind kind, const std::vector<double> &lambda,
                const std::vector<double> &gamma);

  /// The least residual of the earlier and of the later half of a residual history (the later
  /// half takes the extra entry of an odd count; a NaN counts as infinite): the test of the fixed
  /// point's stagnation rule (FixedPointTunables::stagnation_ratio).
  struct HistoryHalves
  {
    std::size_t earlier = 0, later = 0; // entries in each half
    double      earlier_least = 0., later_least = 0.;
  };
  HistoryHalves
  least_of_halves(const std::vector<double> &history);

  /// Binary dump and replay (sand6's d6_solvePrimal idea): the whole ConeProblemData, on streams
  /// (the files are the caller's: core::write_file_atomically, bench/replay_cone_problem).
  void
  write_cone_problem(const ConeProblemData &data, std::ostream &out);
  /// Refuses a stream that is not a consistent dump with std::runtime_error, whose message
  /// completes a sentence about the stream ("is truncated"), for the caller to name it.
  ConeProblemData
  read_cone_problem(std::istream &in);

  /// The case files' names: "pg", "apgd", "spg" (std::invalid_argument otherwise).
  InnerSolver
  parse_inner_solver(const std::string &name);
  std::string
  to_string(InnerSolver s);
  /// The case files' names: "fixed point", "interior point" (std::invalid_argument otherwise).
  ConeMethod
  parse_cone_method(const std::string &name);
} // namespace granflow::solvers
