// Compressed sparse row matrix used at the boundary between the FE models and the solvers, so the
// solvers need no mesh and no deal.II type (DESIGN.md: dependencies point one way).
#pragma once

#include <cstddef>
#include <vector>

namespace granflow::solvers
{
  struct CsrMatrix
  {
    std::size_t         n_rows = 0, n_cols = 0;
    std::vector<int>    row_start; // size n_rows + 1
    std::vector<int>    column;
    std::vector<double> value;

    /// y = M x
    void
    vmult(std::vector<double> &y, const std::vector<double> &x) const
    {
      y.assign(n_rows, 0.);
      for (std::size_t i = 0; i < n_rows; ++i)
        {
          double s = 0.;
          for (int k = row_start[i]; k < row_start[i + 1]; ++k)
            s += value[k] * x[column[k]];
          y[i] = s;
        }
    }

    /// y = M^T x
    void
    Tvmult(std::vector<double> &y, const std::vector<double> &x) const
    {
      y.assign(n_cols, 0.);
      for (std::size_t i = 0; i < n_rows; ++i)
        {
          const double xi = x[i];
          if (xi == 0.)
            continue;
          for (int k = row_start[i]; k < row_start[i + 1]; ++k)
            y[column[k]] += value[k] * xi;
        }
    }
  };
} // namespace granflow::solvers
