// The stall rules the two interior points share (cone_interior_point.cc on the whole law,
// cone_split_interior_point.cc on its split form), with the reason they give in words.
#pragma once

#include "solvers/cone_problem.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

namespace granflow::solvers::detail
{
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
  /// `short_steps` successive steps shorter than `short_step`, or `stagnation_iterations`
  /// iterations without bringing the residual below `stagnation_ratio` times its value at the last
  /// such gain.
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

    /// After the step of length `step` that made `iteration` steps: whether the solve stalls.
    bool
    stalled(const double step, const unsigned int iteration)
    {
      last_step   = step;
      short_steps = step < tune.short_step ? short_steps + 1 : 0;
      return step == 0. || short_steps == tune.short_steps ||
             iteration - progress_iteration >= tune.stagnation_iterations;
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
  };
} // namespace granflow::solvers::detail
