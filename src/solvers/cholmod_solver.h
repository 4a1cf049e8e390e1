// Sparse Cholesky factorisation of the SPD velocity operator A through CHOLMOD (SuiteSparse).
// The dp solver applies A^{-1} hundreds of times per solve (Daviet (36): W = R^+T B A^-1 B^T R^+),
// so A is factorised once and only back-substitutions are repeated.
#pragma once

#include "solvers/sparse.h"

#include <memory>
#include <stdexcept>
#include <vector>

namespace granflow::solvers
{
  /// A is not positive definite: for the velocity operator, some rigid motion is not removed by
  /// the Dirichlet boundaries (the model turns this into bad input).
  class NotPositiveDefinite : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  class CholmodSolver
  {
  public:
    /// Analyses and factorises A (full symmetric storage; only the upper triangle is read); throws
    /// NotPositiveDefinite if A is not.
    explicit CholmodSolver(const CsrMatrix &A);
    ~CholmodSolver();
    CholmodSolver(const CholmodSolver &) = delete;
    CholmodSolver &operator=(const CholmodSolver &) = delete;

    /// x = A^{-1} b
    void
    solve(std::vector<double> &x, const std::vector<double> &b) const;

    std::size_t
    size() const
    {
      return n;
    }

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
    std::size_t           n;
  };
} // namespace granflow::solvers
