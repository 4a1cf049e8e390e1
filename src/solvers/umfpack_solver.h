// Sparse LU factorisation of a square, generally unsymmetric matrix through UMFPACK (SuiteSparse).
// Used by the interior-point method of the cone problem and by ngf's Newton steps, whose matrices
// keep a fixed pattern: the symbolic analysis is done once and each factorize() only redoes the
// numeric factorisation.
#pragma once

#include "solvers/sparse.h"

#include <stdexcept>
#include <vector>

namespace granflow::solvers
{
  /// Thrown by UmfpackSolver::factorize when the matrix is singular (a zero pivot). Every other
  /// failure (out of memory, an invalid matrix) is a plain std::runtime_error: a caller that
  /// answers a singular matrix by changing its problem (a shorter increment) must not mistake
  /// those for one.
  class SingularMatrix : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  class UmfpackSolver
  {
  public:
    /// diagonal_pivoting: symmetric strategy (METIS nested dissection of M + M^T) taking every
    /// nonzero diagonal entry as pivot. Meant for matrices close to symmetric quasi-definite ([P,
    /// B^T; B, -C] with P and C positive definite), for which any symmetric ordering is stable
    /// (Vanderbei 1995); threshold pivoting there rejects the small diagonal entries and multiplies
    /// the fill.
    explicit UmfpackSolver(bool diagonal_pivoting = false);
    ~UmfpackSolver();
    UmfpackSolver(const UmfpackSolver &) = delete;
    UmfpackSolver &
    operator=(const UmfpackSolver &) = delete;

    /// Factorises M. The first call (or a call with a different pattern) also analyses it.
    /// Throws SingularMatrix if M is singular, std::runtime_error (naming UMFPACK's status) if
    /// UMFPACK fails otherwise.
    void
    factorize(const CsrMatrix &M);

    /// x = M^{-1} b
    void
    solve(std::vector<double> &x, const std::vector<double> &b) const;

    /// UMFPACK's own iterative refinement steps in solve() (its default: 2). A caller that refines
    /// on another system sets 0.
    void
    set_refinement_steps(unsigned int steps);

    /// Frees the factorisation and the symbolic analysis.
    void
    release();

  private:
    void               *symbolic = nullptr, *numeric = nullptr;
    const CsrMatrix    *matrix = nullptr; // the last factorised matrix (UMFPACK's solve reads it)
    std::vector<int>    pattern_start, pattern_column;
    std::vector<double> control;
  };
} // namespace granflow::solvers
