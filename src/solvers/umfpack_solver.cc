#include "solvers/umfpack_solver.h"

#include <umfpack.h>

#include <stdexcept>
#include <string>

namespace granflow::solvers
{
  namespace
  {
    /// UMFPACK's status code with its meaning, for messages.
    std::string
    status_text(const int status)
    {
      std::string meaning;
      switch (status)
        {
        case UMFPACK_WARNING_singular_matrix:
          meaning = "singular matrix";
          break;
        case UMFPACK_ERROR_out_of_memory:
          meaning = "out of memory";
          break;
        case UMFPACK_ERROR_invalid_matrix:
          meaning = "invalid matrix";
          break;
        case UMFPACK_ERROR_n_nonpositive:
          meaning = "matrix of no rows";
          break;
        default:
          break;
        }
      return "status " + std::to_string(status) + (meaning.empty() ? "" : ", " + meaning);
    }
  } // namespace

  // A CSR matrix is the CSC storage of its transpose: UMFPACK is given M^T in CSC and solves
  // with UMFPACK_At, i.e. (M^T)^T x = b.

  UmfpackSolver::UmfpackSolver(const bool diagonal_pivoting)
      : control(UMFPACK_CONTROL)
  {
    umfpack_di_defaults(control.data());
    if (diagonal_pivoting)
      {
        control[UMFPACK_STRATEGY]            = UMFPACK_STRATEGY_SYMMETRIC;
        control[UMFPACK_SYM_PIVOT_TOLERANCE] = 0.;
        // Nested dissection (METIS) of M + M^T instead of AMD: on the interior point's augmented
        // system of the 40265-vertex silo (1.1M unknowns) a factorisation takes 9.2 s against
        // 12.9 s, with the same iterates to round-off; on the 673- and 2591-vertex silos the times
        // are equal.
        // UMFPACK_ORDERING_CHOLMOD (the better of AMD and METIS by its own estimate) chose AMD.
        control[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
      }
  }

  UmfpackSolver::~UmfpackSolver()
  {
    release();
  }

  void
  UmfpackSolver::release()
  {
    if (numeric)
      umfpack_di_free_numeric(&numeric);
    if (symbolic)
      umfpack_di_free_symbolic(&symbolic);
    numeric = symbolic = nullptr;
    matrix             = nullptr;
    pattern_start.clear();
    pattern_column.clear();
  }

  void
  UmfpackSolver::set_refinement_steps(const unsigned int steps)
  {
    control[UMFPACK_IRSTEP] = steps;
  }

  void
  UmfpackSolver::factorize(const CsrMatrix &M)
  {
    if (M.n_rows != M.n_cols)
      throw std::invalid_argument("UmfpackSolver: matrix is not square");
    const int n = static_cast<int>(M.n_rows);
    // A failure below leaves no factorisation: solve() then refuses instead of using the factors
    // of a singular matrix (UMFPACK keeps them) or a matrix that may no longer exist.
    if (numeric)
      umfpack_di_free_numeric(&numeric);
    numeric = nullptr;
    matrix  = nullptr;
    if (!symbolic || pattern_start != M.row_start || pattern_column != M.column)
      {
        if (symbolic)
          umfpack_di_free_symbolic(&symbolic);
        const int status = umfpack_di_symbolic(n, n, M.row_start.data(), M.column.data(),
                                               M.value.data(), &symbolic, control.data(), nullptr);
        if (status != UMFPACK_OK)
          throw std::runtime_error("UmfpackSolver: symbolic analysis failed (" +
                                   status_text(status) + ")");
        pattern_start  = M.row_start;
        pattern_column = M.column;
      }
    const int status = umfpack_di_numeric(M.row_start.data(), M.column.data(), M.value.data(),
                                          symbolic, &numeric, control.data(), nullptr);
    if (status != UMFPACK_OK && numeric)
      {
        umfpack_di_free_numeric(&numeric);
        numeric = nullptr;
      }
    if (status == UMFPACK_WARNING_singular_matrix)
      throw SingularMatrix("UmfpackSolver: numeric factorisation failed (" + status_text(status) +
                           ")");
    if (status != UMFPACK_OK)
      throw std::runtime_error("UmfpackSolver: numeric factorisation failed (" +
                               status_text(status) + ")");
    matrix = &M;
  }

  void
  UmfpackSolver::solve(std::vector<double> &x, const std::vector<double> &b) const
  {
    if (!numeric)
      throw std::logic_error("UmfpackSolver::solve before factorize");
    x.assign(b.size(), 0.);
    const int status = umfpack_di_solve(UMFPACK_At, matrix->row_start.data(), matrix->column.data(),
                                        matrix->value.data(), x.data(), b.data(), numeric,
                                        control.data(), nullptr);
    if (status != UMFPACK_OK)
      throw std::runtime_error("UmfpackSolver: solve failed (" + status_text(status) + ")");
  }
} // namespace granflow::solvers
