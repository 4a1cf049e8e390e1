// Bookkeeping shared by the outer loops of the cone solvers (Cadoux's fixed point in
// cone_solver.cc, the interior point in cone_interior_point.cc): residual and time histories, the
// least residual so far (neither iteration is monotone, so the best iterate is what they return),
// progress reports and the stopping tests of ConeSolverOptions.
#pragma once

#include "solvers/cone_problem.h"

#include <cmath>
#include <limits>

namespace granflow::solvers::detail
{
  class SolveMonitor
  {
  public:
    SolveMonitor(const ConeSolverOptions &options, ConeSolverStats &stats)
        : options(options)
        , stats(stats)
    {
    }

    /// Records the residual of the current iterate, `elapsed` seconds into the solve, in `stats`.
    /// Returns true if it is the least so far, which the caller keeps. The first iterate always
    /// counts (even at an infinite or NaN residual, so that there is one to return); a NaN never
    /// replaces a number, and any later residual replaces a NaN.
    bool
    record(const double residual, const double elapsed)
    {
      stats.residual = residual;
      stats.residual_history.push_back(residual);
      stats.time_history.push_back(elapsed);
      if (recorded && !std::isnan(best_residual) && !(residual < best_residual))
        return false;
      recorded      = true;
      best_residual = residual;
      return true;
    }

    /// Called once the iterate is logged: reports progress, then tells whether the loop ends
    /// (tolerance reached, which sets stats.converged; a stop request, which sets
    /// stats.interrupted; or the iteration or time limit). With `predict`, for iterations that
    /// cannot be interrupted, the time limit also ends the loop where the next iteration would,
    /// at the last one's duration (at the first, the setup's), end past it.
    bool
    finished(const bool predict = false)
    {
      if (options.progress)
        options.progress(stats.outer_iterations, stats.residual);
      if (stats.residual <= options.tolerance)
        {
          stats.converged = true;
          return true;
        }
      if (options.stop_requested && options.stop_requested())
        {
          stats.interrupted = true;
          return true;
        }
      const auto  &t    = stats.time_history;
      const double last = t.size() > 1 ? t.back() - t[t.size() - 2] : t.back();
      stats.timed_out =
          options.max_seconds > 0. && t.back() + (predict ? last : 0.) > options.max_seconds;
      return stats.outer_iterations == options.max_outer_iterations || stats.timed_out;
    }

    double
    least_residual() const
    {
      return best_residual;
    }

  private:
    const ConeSolverOptions &options;
    ConeSolverStats         &stats;
    double                   best_residual = std::numeric_limits<double>::infinity();
    bool                     recorded      = false;
  };
} // namespace granflow::solvers::detail
