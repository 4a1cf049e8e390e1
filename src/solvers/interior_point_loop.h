// What the two interior points share (cone_interior_point.cc on the whole law,
// cone_split_interior_point.cc on its split form): their scope, their stall rules with the reason
// they give in words, and their outer loop.
#pragma once

#include "solvers/cone_problem.h"
#include "solvers/solve_monitor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace granflow::solvers::detail
{
  inline double
  norm_inf(const std::vector<double> &v)
  {
    double r = 0.;
    for (const double x : v)
      if (const double a = std::abs(x); a > r || std::isnan(a))
        r = a; // std::max would drop a NaN
    return r;
  }

  /// The two interior points: on the split form of the law (cone_split_interior_point.cc) and on
  /// the whole problem (cone_interior_point.cc).
  enum class InteriorPointForm
  {
    split,
    whole
  };

  /// Whether `form` handles the problem's mu and Bi at every point: the whole form needs mu > 0
  /// and Bi = 0; the split form a friction cone with an interior, mu >= 0 and Bi >= 0 not both 0.
  inline bool
  interior_point_handles(const ConeProblemData &data, const InteriorPointForm form)
  {
    for (std::size_t i = 0; i < data.n_points(); ++i)
      if (form == InteriorPointForm::whole
              ? !(data.mu[i] > 0.) || data.Bi[i] != 0.
              : !(data.mu[i] >= 0. && data.Bi[i] >= 0. && data.mu[i] + data.Bi[i] > 0.))
        return false;
    return true;
  }

  /// Throws std::invalid_argument unless interior_point_handles(data, form).
  inline void
  check_interior_point_scope(const ConeProblemData &data, const InteriorPointForm form)
  {
    if (!interior_point_handles(data, form))
      throw std::invalid_argument(
          form == InteriorPointForm::whole
              ? "the interior point on the whole problem needs mu > 0 and Bi = 0 at every "
                "constraint point (use its split form or the Cadoux fixed point otherwise)"
              : "the interior-point method needs mu > 0 or Bi > 0 at every constraint point "
                "(use the Cadoux fixed point otherwise)");
  }

  /// The step `t` halved until `interior(t)` holds (rounding can still put a block on the
  /// boundary at the longest step computed); 0 once it falls to 1e-12.
  template <typename Interior>
  double
  halve_until_interior(double t, const Interior &interior)
  {
    while (t > 1e-12 && !interior(t))
      t *= 0.5;
    return t > 1e-12 ? t : 0.;
  }

  /// A tunable's value as a user writes it: 1e-4 (not 0.0001), 0.5, 3.
  inline std::string
  as_written(const double v)
  {
    std::ostringstream s;
    if (v != 0. && std::abs(v) < 1e-3)
      {
        const int    e = static_cast<int>(std::floor(std::log10(std::abs(v))));
        const double m = v / std::pow(10., e);
        s << std::setprecision(3) << m << 'e' << e;
      }
    else
      s << v;
    return s.str();
  }

  /// InteriorPointTunables' stall rules: a step of 0 (no step keeps the iterate interior),
  /// `short_steps` successive steps shorter than `short_step`, `stagnation_iterations`
  /// iterations without bringing the residual below `stagnation_ratio` times its value at the last
  /// such gain, or (beat_within > 0) beat_within iterations without a residual below
  /// beat_residual.
  class StallRules
  {
  public:
    explicit StallRules(const InteriorPointTunables &tune)
        : tune(tune)
    {
    }

    /// The residual of the iterate reached after `iteration` steps.
    void
    record(const double residual, const unsigned int iteration)
    {
      if (residual < tune.stagnation_ratio * progress_mark)
        {
          progress_mark      = residual;
          progress_iteration = iteration;
        }
    }

    /// After the step of length `step` that made `iteration` steps, the least residual so far
    /// `least_residual` (the solve's monitor keeps it): whether the solve stalls.
    bool
    stalled(const double step, const unsigned int iteration, const double least_residual)
    {
      last_step   = step;
      least       = least_residual;
      short_steps = step < tune.short_step ? short_steps + 1 : 0;
      not_beaten =
          tune.beat_within > 0 && iteration >= tune.beat_within && !(least < tune.beat_residual);
      return step == 0. || short_steps == tune.short_steps ||
             iteration - progress_iteration >= tune.stagnation_iterations || not_beaten;
    }

    /// Which rule ended the solve, in words; `factorization_failure`: UMFPACK's message, if a
    /// Newton matrix could not be factorised (which the step of 0 then stands for).
    std::string
    reason(const std::string &factorization_failure) const
    {
      std::ostringstream s;
      if (!factorization_failure.empty())
        s << "the Newton matrix could not be factorised (" << factorization_failure << ")";
      else if (last_step == 0.)
        s << "no step kept the iterate interior (rounding)";
      else if (not_beaten)
        s << tune.beat_within << " iterations did not bring the residual below "
          << as_written(tune.beat_residual) << " (its least: " << as_written(least) << ")";
      else if (short_steps == tune.short_steps)
        s << tune.short_steps << " successive steps were shorter than "
          << as_written(tune.short_step) << " (the iterates left the central path)";
      else
        s << tune.stagnation_iterations << " iterations gained less than "
          << as_written(100. * (1. - tune.stagnation_ratio)) << " % on the least residual";
      return s.str();
    }

  private:
    const InteriorPointTunables &tune;
    unsigned int                 short_steps = 0, progress_iteration = 0;
    double                       progress_mark = std::numeric_limits<double>::infinity();
    double                       last_step     = 0.;
    double                       least         = 0.; // as stalled() was given it
    bool                         not_beaten    = false;
  };

  /// The outer loop of both interior points, from the iterate `method` holds: each iterate's
  /// residual is recorded and logged, the least one's iterate kept and returned in `solution`,
  /// and the loop ends on the options' tolerance and limits or on the stall rules. `t0`: when the
  /// solve began. `Method` provides
  ///   double residual()                    evaluates the current iterate, returns its residual
  ///   void   keep(ConeSolution &) const    copies the current iterate's u, lambda and gamma
  ///   void   log_columns(std::ostream &)   its gap (width 14), primal and dual residuals (13)
  ///   double newton_step()                 steps; returns the step length (0: none)
  ///   void   stepped(unsigned int)         after the step that made that many (may log)
  ///   std::string  failure()               UMFPACK's message if a factorisation failed
  ///   unsigned int n_factorizations()
  template <typename Method>
  ConeSolverStats
  run_interior_point(Method &method, const ConeSolverOptions &options, ConeSolution &solution,
                     const std::chrono::steady_clock::time_point t0)
  {
    ConeSolverStats stats;
    SolveMonitor    monitor(options, stats);
    StallRules      rules(options.interior_point);
    double          step = 0.;
    for (;;)
      {
        const double residual = method.residual();
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (monitor.record(residual, elapsed))
          method.keep(solution);
        rules.record(stats.residual, stats.outer_iterations);
        if (options.log)
          {
            std::ostream &log = *options.log;
            log << std::setw(7) << stats.outer_iterations << std::setw(14) << std::scientific
                << std::setprecision(4) << stats.residual;
            method.log_columns(log);
            log << std::setw(10) << std::fixed << std::setprecision(4) << step << std::setw(13)
                << std::setprecision(3) << elapsed << std::endl
                << std::defaultfloat;
          }
        // An iteration (one factorisation) is not interrupted: none is started that would, at
        // the last one's duration, end past the time limit.
        if (monitor.finished(true))
          break;
        step = method.newton_step();
        ++stats.outer_iterations;
        method.stepped(stats.outer_iterations);
        // No step keeps the iterate interior (rounding has taken over), or the iterates have left
        // the central path and only crawl, or the residual stagnates: stop with the best iterate.
        if (rules.stalled(step, stats.outer_iterations, monitor.least_residual()))
          {
            stats.stalled      = true;
            stats.stall_reason = rules.reason(method.failure());
            break;
          }
      }
    stats.time_solve = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats.operator_applications = method.n_factorizations();
    stats.residual              = monitor.least_residual();
    return stats;
  }

  /// Method<block_size>(data, options).solve(solution), with the construction (the patterns,
  /// any factorisation of A) timed as stats.time_factorize, as the fixed point's factorisation
  /// of A is.
  template <template <std::size_t> class Method, typename... Extra>
  ConeSolverStats
  construct_and_solve(const ConeProblemData &data, const ConeSolverOptions &options,
                      ConeSolution &solution, const Extra &...extra)
  {
    const auto t0  = std::chrono::steady_clock::now();
    const auto run = [&](auto &&method) {
      const double setup =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ConeSolverStats stats = method.solve(solution);
      stats.time_factorize  = setup;
      return stats;
    };
    if (data.block_size == 3)
      return run(Method<3>(data, options, extra...));
    if (data.block_size == 6)
      return run(Method<6>(data, options, extra...));
    throw std::invalid_argument("solve_cone_problem: block size must be 3 (2D) or 6 (3D)");
  }
} // namespace granflow::solvers::detail
