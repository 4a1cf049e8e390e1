// Newton-Raphson for a coupled residual of several fields (the ngf model's displacement and
// fluidity, Henann & Kamrin 2016, Section 5), with a backtracking line search and, optionally,
// modified Newton steps that reuse the last factorised Jacobian. Each field's residual is
// normalised by its own scale (Section 6.1: R_u, R_g), and the iteration converges when every
// normalised residual is below the tolerance. Options / Stats as for the cone solvers
// (cone_problem.h); the problem is an interface, so the driver knows nothing of meshes.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace granflow::solvers
{
  struct NewtonOptions
  {
    double       tolerance      = 1e-6; // on every field's normalised residual
    unsigned int max_iterations = 12;
    /// Modified Newton: a step may reuse the last factorised Jacobian (also across calls) if it
    /// reduces the merit max_f R_f at least by reuse_contraction; otherwise the step is undone
    /// and the Jacobian factorised afresh.
    bool   reuse_factorization = true;
    double reuse_contraction   = 0.25;
    /// Backtracking: the step is halved until the merit falls by (1 - armijo alpha); after
    /// max_halvings the short step is taken as it is.
    double       armijo       = 1e-4;
    unsigned int max_halvings = 6;
    /// At the residuals' round-off floor the full correction tells convergence: below this
    /// fraction of each field's largest value (L_inf) it changes nothing one could see.
    double negligible_correction = 1e-10;
    /// Fixed-column table: label, iteration, the normalised residuals; the relative corrections;
    /// line-search steps.
    std::ostream *log = nullptr;
    /// Asked before each correction (a Ctrl-C, core/interrupt.h): true ends the solve, not
    /// converged, with NewtonStats::interrupted.
    std::function<bool()> stop_requested;
  };

  /// Per field: the residual's norm and the scale that normalises it (0: not normalised).
  struct FieldResiduals
  {
    std::vector<double> norm, scale;

    /// norm_f / scale_f, with another evaluation's scales (those of the step's start).
    double
    normalized(const std::size_t f, const FieldResiduals &scales) const
    {
      return scales.scale[f] > 0. ? norm[f] / scales.scale[f] : norm[f];
    }
  };

  struct CorrectionSize
  {
    double change, magnitude; // L_inf of a field's correction and of its value
    double
    relative() const
    {
      return magnitude > 0. ? change / magnitude : change;
    }
  };

  /// The merit max_f R_f; NaN if any residual is not a number, or infinite.
  inline double
  merit(const std::vector<double> &residuals)
  {
    double m = 0.;
    for (const double R : residuals)
      m = std::isfinite(R) ? std::max(m, R) : std::numeric_limits<double>::quiet_NaN();
    return m;
  }

  struct NewtonIterate
  {
    std::vector<double> residual; // normalised, per field
    /// The full correction from this iterate (before the line search and make_admissible()),
    /// per field, CorrectionSize::relative(); NaN where none was computed (the last iterate).
    std::vector<double> correction;
    bool                fresh = true; // its Jacobian was factorised afresh
  };

  struct NewtonStats
  {
    bool                       converged  = false;
    bool                       singular   = false; // a Jacobian could not be factorised
    bool                       interrupted = false; // ended by NewtonOptions::stop_requested
    /// The index of the last iterate: the corrections taken (a negligible last one, which
    /// ends the solve, is applied but not counted).
    unsigned int               iterations = 0;
    std::vector<NewtonIterate> history;
  };

  /// What the driver needs of a problem; x is its iterate, which the driver updates in place.
  /// VectorType: copyable, with x.add(alpha, y) for x += alpha y.
  template <typename VectorType> class NewtonProblem
  {
  public:
    virtual ~NewtonProblem() = default;

    virtual VectorType &
    iterate() = 0;
    /// The residual at the iterate, and the Jacobian if asked (not yet factorised).
    virtual FieldResiduals
    residual(bool with_jacobian) = 0;
    /// dx = -J^-1 r for the residual last evaluated, with the Jacobian last assembled (factorised
    /// first, if `factorize`) or the last factorised one. False if it cannot be factorised.
    virtual bool
    correction(VectorType &dx, bool factorize) = 0;
    /// Per field, the L_inf norms of dx and of the iterate.
    virtual std::vector<CorrectionSize>
    correction_sizes(const VectorType &dx) const = 0;
    /// Moves an iterate into the problem's admissible set after each step (e.g. g >= 0).
    virtual void
    make_admissible(VectorType &)
    {
    }
  };

  /// Keeps, across solves, whether a factorised Jacobian exists that a modified step may reuse.
  template <typename VectorType> class NewtonSolver
  {
  public:
    explicit NewtonSolver(const NewtonOptions &options)
        : options(options)
    {
    }

    /// Iterates from problem.iterate() until every normalised residual is below the tolerance,
    /// or the correction is negligible (converged), or max_iterations corrections, a non-finite
    /// residual or a singular Jacobian (not converged: the caller cuts its increment). `label`
    /// opens each line of the log's table (e.g. the increment).
    NewtonStats
    solve(NewtonProblem<VectorType> &problem, const unsigned int label)
    {
      NewtonStats    stats;
      VectorType    &x = problem.iterate();
      VectorType     dx(x), x_start(x);
      FieldResiduals r;
      bool           have_residual = false; // r belongs to the current x
      for (stats.iterations = 0;; ++stats.iterations)
        {
          const bool fresh = !options.reuse_factorization || !factorization_valid;
          if (!have_residual || fresh)
            r = problem.residual(fresh);
          have_residual = false;
          NewtonIterate it;
          it.fresh = fresh;
          for (std::size_t f = 0; f < r.norm.size(); ++f)
            it.residual.push_back(r.normalized(f, r));
          it.correction.assign(r.norm.size(), std::numeric_limits<double>::quiet_NaN());
          stats.history.push_back(it);
          if (options.log)
            {
              *options.log << std::setw(6) << label << std::setw(6) << stats.iterations
                           << std::scientific << std::setprecision(3);
              for (const double R : it.residual)
                *options.log << std::setw(12) << R;
              *options.log << std::defaultfloat << (fresh ? "" : "  (previous factorization)")
                           << '\n';
            }
          const double merit0 = merit(it.residual);
          if (std::isnan(merit0))
            return stats;
          if (merit0 <= options.tolerance)
            {
              stats.converged = true;
              return stats;
            }
          if (stats.iterations == options.max_iterations)
            return stats;
          if (options.stop_requested && options.stop_requested())
            {
              stats.interrupted = true;
              return stats;
            }
          if (!problem.correction(dx, fresh))
            {
              factorization_valid = false;
              stats.singular      = true;
              if (options.log)
                *options.log << std::setw(36) << "singular Jacobian" << '\n';
              return stats; // the increment is cut
            }
          if (fresh)
            factorization_valid = true;
          const std::vector<CorrectionSize> size = problem.correction_sizes(dx);
          for (std::size_t f = 0; f < size.size(); ++f)
            stats.history.back().correction[f] = size[f].relative();
          if (options.log)
            {
              *options.log << std::setw(36) << "correction" << std::scientific
                           << std::setprecision(3);
              for (const double c : stats.history.back().correction)
                *options.log << std::setw(12) << c;
              *options.log << std::defaultfloat << '\n';
            }
          if (fresh && std::all_of(size.begin(), size.end(), [&](const CorrectionSize &c) {
                return c.change <= options.negligible_correction * c.magnitude;
              }))
            {
              x.add(1., dx);
              stats.converged = true;
              return stats;
            }
          // Backtracking on the merit with this iterate's scales: the full step is taken
          // whenever it reduces the merit (always, near the solution), which keeps the quadratic
          // rate; it is halved where the problem is far from linear (for ngf: the onset of flow,
          // a free surface).
          x_start      = x;
          double alpha = 1.;
          for (unsigned int k = 0;; ++k, alpha *= 0.5)
            {
              x = x_start;
              x.add(alpha, dx);
              problem.make_admissible(x);
              if (k == options.max_halvings)
                break; // a short step is taken (only a fresh Jacobian's: a reused one is
                       // abandoned at k = 0), and the next step may reuse its factorisation
              const FieldResiduals m = problem.residual(false);
              std::vector<double>  R(m.norm.size()); // with the step's start's scales
              for (std::size_t f = 0; f < R.size(); ++f)
                R[f] = m.normalized(f, r);
              const double merit_k = merit(R);
              if (!fresh && !(merit_k <= options.reuse_contraction * merit0))
                {
                  x                   = x_start;
                  factorization_valid = false;
                  break;
                }
              if (merit_k <= (1. - options.armijo * alpha) * merit0)
                {
                  r             = m;
                  have_residual = true;
                  break;
                }
            }
          if (alpha < 1. && options.log)
            *options.log << std::setw(36) << "line search step" << std::setw(12) << alpha << '\n';
        }
    }

  private:
    NewtonOptions options;
    bool          factorization_valid = false;
  };
} // namespace granflow::solvers
