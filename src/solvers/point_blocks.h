// Each constraint point's rows of H as a small dense block on the union of their columns, and the
// velocity matrix R = A + sum_i H_i^T M_i H_i that the interior points factorise once they have
// eliminated the stress (cone_interior_point.cc, cone_split_interior_point.cc); M_i is the
// point's block_size x block_size block.
#pragma once

#include "solvers/cone_problem.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace granflow::solvers::detail
{
  class PointBlocks
  {
  public:
    explicit PointBlocks(const ConeProblemData &data)
        : data(data)
        , n(data.block_size)
        , columns_(data.n_points())
        , H_(data.n_points())
    {
      for (std::size_t i = 0; i < columns_.size(); ++i)
        {
          auto &cols = columns_[i];
          for (std::size_t a = 0; a < n; ++a)
            for (int k = data.H.row_start[i * n + a]; k < data.H.row_start[i * n + a + 1]; ++k)
              cols.push_back(data.H.column[k]);
          std::sort(cols.begin(), cols.end());
          cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
          H_[i].assign(n * cols.size(), 0.);
          for (std::size_t a = 0; a < n; ++a)
            for (int k = data.H.row_start[i * n + a]; k < data.H.row_start[i * n + a + 1]; ++k)
              {
                const auto c =
                    std::lower_bound(cols.begin(), cols.end(), data.H.column[k]) - cols.begin();
                H_[i][a * cols.size() + c] += data.H.value[k];
              }
        }
    }

    /// The sorted union of the columns of point i's rows of H.
    const std::vector<int> &
    columns(const std::size_t i) const
    {
      return columns_[i];
    }

    /// Point i's rows of H on columns(i): n x |columns(i)|, row-major.
    const double *
    H(const std::size_t i) const
    {
      return H_[i].data();
    }

    /// The pattern of R (velocity unknowns only): A's, and every pair of a point's columns; and
    /// where A's entries go in R.value. A point's products are placed by merging its sorted
    /// columns with R's rows, which costs no memory: |cols|^2 positions per point would, 1.4 GB
    /// on a large P1 mesh.
    void
    build_reduced_pattern()
    {
      const std::size_t             n_u = data.A.n_rows;
      std::vector<std::vector<int>> rows(n_u);
      for (std::size_t r = 0; r < n_u; ++r)
        for (int k = data.A.row_start[r]; k < data.A.row_start[r + 1]; ++k)
          rows[r].push_back(data.A.column[k]);
      for (const auto &cols : columns_)
        for (const int r : cols)
          rows[r].insert(rows[r].end(), cols.begin(), cols.end());
      R.n_rows = R.n_cols = n_u;
      R.row_start.assign(1, 0);
      R.column.clear();
      for (auto &row : rows)
        {
          std::sort(row.begin(), row.end());
          row.erase(std::unique(row.begin(), row.end()), row.end());
          R.column.insert(R.column.end(), row.begin(), row.end());
          R.row_start.push_back(static_cast<int>(R.column.size()));
        }
      R.value.assign(R.column.size(), 0.);
      A_position.clear();
      for (std::size_t r = 0; r < n_u; ++r)
        for (int k = data.A.row_start[r]; k < data.A.row_start[r + 1]; ++k)
          {
            const auto first = R.column.begin() + R.row_start[r];
            const auto last  = R.column.begin() + R.row_start[r + 1];
            A_position.push_back(static_cast<int>(std::lower_bound(first, last, data.A.column[k]) -
                                                  R.column.begin()));
          }
    }

    /// R = A + sum_i H_i^T M[i] H_i (build_reduced_pattern() first). Matrix: M[i][a][b].
    template <typename Matrix>
    const CsrMatrix &
    reduced(const std::vector<Matrix> &M)
    {
      std::fill(R.value.begin(), R.value.end(), 0.);
      for (std::size_t k = 0; k < A_position.size(); ++k)
        R.value[A_position[k]] += data.A.value[k];
      std::vector<double> G;
      for (std::size_t i = 0; i < columns_.size(); ++i)
        {
          const auto       &cols = columns_[i];
          const std::size_t nc   = cols.size();
          const double     *Hi   = H_[i].data();
          G.assign(n * nc, 0.); // G = M_i H_i
          for (std::size_t a = 0; a < n; ++a)
            for (std::size_t b = 0; b < n; ++b)
              if (M[i][a][b] != 0.)
                for (std::size_t c = 0; c < nc; ++c)
                  G[a * nc + c] += M[i][a][b] * Hi[b * nc + c];
          for (std::size_t r = 0; r < nc; ++r) // H_i^T G into row cols[r], merged with it
            {
              int k = R.row_start[cols[r]];
              for (std::size_t c = 0; c < nc; ++c)
                {
                  while (R.column[k] < cols[c])
                    ++k;
                  double v = 0.;
                  for (std::size_t a = 0; a < n; ++a)
                    v += Hi[a * nc + r] * G[a * nc + c];
                  R.value[k] += v;
                }
            }
        }
      return R;
    }

  private:
    const ConeProblemData           &data;
    const std::size_t                n;
    std::vector<std::vector<int>>    columns_;
    std::vector<std::vector<double>> H_;
    CsrMatrix                        R;
    std::vector<int>                 A_position;
  };
} // namespace granflow::solvers::detail
