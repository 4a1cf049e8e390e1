// Small dense linear systems (a handful to a few thousand unknowns, e.g. the least-squares problem
// of Anderson acceleration or the Newton step of a 1D reference solution): Gaussian elimination
// with partial pivoting. Header-only, so that postprocess/ can use it without linking the solvers.
#pragma once

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace granflow::solvers
{
  /// Solves A x = b given as the augmented k x (k + 1) matrix M = [A | b], which is overwritten.
  /// Returns false, with x untouched, if a pivot is exactly zero (A singular).
  inline bool
  solve_augmented(std::vector<std::vector<double>> &M, std::vector<double> &x)
  {
    const std::size_t k = M.size();
    for (std::size_t a = 0; a < k; ++a)
      {
        std::size_t pivot = a;
        for (std::size_t b = a + 1; b < k; ++b)
          if (std::abs(M[b][a]) > std::abs(M[pivot][a]))
            pivot = b;
        std::swap(M[a], M[pivot]);
        if (M[a][a] == 0.)
          return false;
        for (std::size_t b = a + 1; b < k; ++b)
          {
            const double r = M[b][a] / M[a][a];
            for (std::size_t c = a; c <= k; ++c)
              M[b][c] -= r * M[a][c];
          }
      }
    x.assign(k, 0.);
    for (std::size_t a = k; a-- > 0;)
      {
        double r = M[a][k];
        for (std::size_t b = a + 1; b < k; ++b)
          r -= M[a][b] * x[b];
        x[a] = r / M[a][a];
      }
    return true;
  }
} // namespace granflow::solvers
