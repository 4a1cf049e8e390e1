#include "solvers/cholmod_solver.h"

#include <cholmod.h>

#include <cstring>
#include <stdexcept>

namespace granflow::solvers
{
  struct CholmodSolver::Impl
  {
    cholmod_common  common;
    cholmod_factor *factor = nullptr;
    cholmod_dense  *rhs    = nullptr;
    // Workspace of cholmod_solve2, reused across the hundreds of solves of a cone problem.
    cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;

    Impl() { cholmod_start(&common); }
    ~Impl()
    {
      for (cholmod_dense **d : {&X, &Y, &E, &rhs})
        if (*d)
          cholmod_free_dense(d, &common);
      if (factor)
        cholmod_free_factor(&factor, &common);
      cholmod_finish(&common);
    }
  };

  CholmodSolver::CholmodSolver(const CsrMatrix &A)
    : impl(std::make_unique<Impl>())
    , n(A.n_rows)
  {
    if (A.n_rows != A.n_cols)
      throw std::invalid_argument("CholmodSolver: matrix is not square");
    cholmod_common &c = impl->common;
    c.print           = 0; // a failure is reported by the exception below, not on stderr
    // CSR of a symmetric matrix is its CSC; stype = 1 reads the upper triangle only.
    cholmod_sparse *M = cholmod_allocate_sparse(n, n, A.value.size(), 1, 1, 1, CHOLMOD_REAL, &c);
    std::memcpy(M->p, A.row_start.data(), sizeof(int) * (n + 1));
    std::memcpy(M->i, A.column.data(), sizeof(int) * A.column.size());
    std::memcpy(M->x, A.value.data(), sizeof(double) * A.value.size());
    impl->factor = cholmod_analyze(M, &c);
    cholmod_factorize(M, impl->factor, &c);
    bool ok = c.status == CHOLMOD_OK && impl->factor->minor == n;
    // For a small or very sparse matrix CHOLMOD chooses a simplicial LDL' factorisation, which
    // accepts negative pivots: an indefinite A would pass. Its D (each column's first entry, the
    // diagonal) must be positive as well.
    if (ok && !impl->factor->is_ll)
      {
        const auto *column_start = static_cast<const int *>(impl->factor->p);
        const auto *entries      = static_cast<const double *>(impl->factor->x);
        for (std::size_t j = 0; j < n && ok; ++j)
          ok = entries[column_start[j]] > 0.;
      }
    cholmod_free_sparse(&M, &c);
    if (!ok)
      throw NotPositiveDefinite("CholmodSolver: the velocity operator A is not positive definite "
                                "(is every rigid motion removed by the Dirichlet boundaries?)");
    impl->rhs = cholmod_zeros(n, 1, CHOLMOD_REAL, &c);
  }

  CholmodSolver::~CholmodSolver() = default;

  void
  CholmodSolver::solve(std::vector<double> &x, const std::vector<double> &b) const
  {
    cholmod_common &c = impl->common;
    std::memcpy(impl->rhs->x, b.data(), sizeof(double) * n);
    cholmod_solve2(CHOLMOD_A, impl->factor, impl->rhs, nullptr, &impl->X, nullptr, &impl->Y, &impl->E, &c);
    x.resize(n);
    std::memcpy(x.data(), impl->X->x, sizeof(double) * n);
  }
} // namespace granflow::solvers
