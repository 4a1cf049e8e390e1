// GMRES (Saad & Schultz 1986) without restart, for the small matrix-free systems of the solvers:
// the Arnoldi basis by modified Gram-Schmidt, the least-squares problem by Givens rotations.
#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

namespace granflow::solvers::detail
{
  struct GmresResult
  {
    unsigned int iterations        = 0;
    double       relative_residual = 0.; // ||b - M x|| / ||b||, as the rotations estimate it
  };

  /// Solves M x = b from x = 0, where apply(v, Mv) sets Mv = M v, until the residual is below
  /// relative_tolerance ||b|| or after max_iterations products. b = 0 gives x = 0.
  inline GmresResult
  gmres(const std::function<void(const std::vector<double> &, std::vector<double> &)> &apply,
        const std::vector<double> &b, std::vector<double> &x, const double relative_tolerance,
        const unsigned int max_iterations)
  {
    const std::size_t n   = b.size();
    const auto        dot = [n](const std::vector<double> &a, const std::vector<double> &c) {
      double sum = 0.;
      for (std::size_t k = 0; k < n; ++k)
        sum += a[k] * c[k];
      return sum;
    };
    x.assign(n, 0.);
    GmresResult  result;
    const double beta = std::sqrt(dot(b, b));
    if (!(beta > 0.))
      return result;
    std::vector<std::vector<double>> V{b};
    for (double &v : V[0])
      v /= beta;
    std::vector<std::vector<double>> R;               // the rotated Hessenberg columns
    std::vector<double>              cs, sn, g{beta}; // rotations and rotated right-hand side
    double                           residual = beta;
    std::vector<double>              w;
    while (result.iterations < max_iterations && residual > relative_tolerance * beta)
      {
        const std::size_t j = result.iterations;
        apply(V[j], w);
        std::vector<double> h(j + 2, 0.);
        for (std::size_t i = 0; i <= j; ++i)
          {
            h[i] = dot(w, V[i]);
            for (std::size_t k = 0; k < n; ++k)
              w[k] -= h[i] * V[i][k];
          }
        h[j + 1] = std::sqrt(dot(w, w));
        for (std::size_t i = 0; i < j; ++i)
          {
            const double t = cs[i] * h[i] + sn[i] * h[i + 1];
            h[i + 1]       = -sn[i] * h[i] + cs[i] * h[i + 1];
            h[i]           = t;
          }
        const double r = std::hypot(h[j], h[j + 1]);
        cs.push_back(r > 0. ? h[j] / r : 1.);
        sn.push_back(r > 0. ? h[j + 1] / r : 0.);
        h[j] = r;
        g.push_back(-sn[j] * g[j]);
        g[j] *= cs[j];
        residual            = std::abs(g[j + 1]);
        const double norm_w = h[j + 1];
        h.resize(j + 1);
        R.push_back(std::move(h));
        ++result.iterations;
        if (!(norm_w > 0.) || !(r > 0.)) // invariant subspace (or breakdown): x is exact here
          break;
        for (double &v : w)
          v /= norm_w;
        V.push_back(w);
      }
    // y = R^-1 g by back substitution, x = V y
    const std::size_t   k = R.size();
    std::vector<double> y(k, 0.);
    for (std::size_t i = k; i-- > 0;)
      {
        double v = g[i];
        for (std::size_t c = i + 1; c < k; ++c)
          v -= R[c][i] * y[c];
        y[i] = R[i][i] != 0. ? v / R[i][i] : 0.;
      }
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t c = 0; c < n; ++c)
        x[c] += y[i] * V[i][c];
    result.relative_residual = residual / beta;
    return result;
  }
} // namespace granflow::solvers::detail
