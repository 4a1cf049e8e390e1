// Jordan algebra of the second-order cone K_1 = {x_0 >= ||x_bar||} in R^n, for the interior
// points of the cone problem (cone_interior_point.cc, cone_split_interior_point.cc).
#pragma once

#include "rheology/drucker_prager.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace granflow::solvers::detail
{
  /// Jordan algebra of the second-order cone K_1 = {x_0 >= ||x_bar||} in R^n.
  template <std::size_t n> struct Soc
  {
    using Block  = std::array<double, n>;
    using Matrix = std::array<std::array<double, n>, n>;

    /// x^T J y, J = diag(1, -1, ..., -1)
    static double
    jdot(const Block &x, const Block &y)
    {
      double s = x[0] * y[0];
      for (std::size_t j = 1; j < n; ++j)
        s -= x[j] * y[j];
      return s;
    }

    static double
    dot(const Block &x, const Block &y)
    {
      double s = 0.;
      for (std::size_t j = 0; j < n; ++j)
        s += x[j] * y[j];
      return s;
    }

    /// x o y = (x . y, x_0 y_bar + y_0 x_bar)
    static Block
    product(const Block &x, const Block &y)
    {
      Block r;
      r[0] = dot(x, y);
      for (std::size_t j = 1; j < n; ++j)
        r[j] = x[0] * y[j] + y[0] * x[j];
      return r;
    }

    /// v with lambda o v = r (lambda in the interior of K_1)
    static Block
    arrow_solve(const Block &lambda, const Block &r)
    {
      Block  v;
      double lr = 0.;
      for (std::size_t j = 1; j < n; ++j)
        lr += lambda[j] * r[j];
      v[0] = (lambda[0] * r[0] - lr) / jdot(lambda, lambda);
      for (std::size_t j = 1; j < n; ++j)
        v[j] = (r[j] - v[0] * lambda[j]) / lambda[0];
      return v;
    }

    /// x^p by the spectral decomposition, x in the interior of K_1. The small eigenvalue
    /// x_0 - ||x_bar|| is computed as det(x) / (x_0 + ||x_bar||), without cancellation.
    static Block
    power(const Block &x, const double p)
    {
      const double nb = rheology::norm_T(x), big = x[0] + nb;
      const double small = (x[0] - nb) * big > 0. ? jdot(x, x) / big : 0.;
      const double a = std::pow(small, p), b = std::pow(big, p);
      Block        r;
      r[0] = 0.5 * (a + b);
      for (std::size_t j = 1; j < n; ++j)
        r[j] = nb > 0. ? 0.5 * (b - a) * x[j] / nb : 0.;
      return r;
    }

    /// Quadratic representation P(x) = 2 x x^T - det(x) J.
    static Matrix
    quadratic_representation(const Block &x)
    {
      const double det = jdot(x, x);
      Matrix       P;
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b)
          P[a][b] = 2. * x[a] * x[b] - (a == b ? (a == 0 ? det : -det) : 0.);
      return P;
    }

    static Block
    apply(const Matrix &M, const Block &x)
    {
      Block r{};
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b)
          r[a] += M[a][b] * x[b];
      return r;
    }

    static Matrix
    multiply(const Matrix &M, const Matrix &N)
    {
      Matrix r{};
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t c = 0; c < n; ++c)
          for (std::size_t b = 0; b < n; ++b)
            r[a][b] += M[a][c] * N[c][b];
      return r;
    }

    /// Nesterov-Todd scaling of (s, z): the scaling point w with P(w) z = s, W = P(w^-1/2),
    /// W^-1 = P(w^1/2); then W s = W^-1 z.
    static void
    nesterov_todd(const Block &s, const Block &z, Matrix &W, Matrix &W_inv)
    {
      const Matrix Ps = quadratic_representation(power(s, 0.5));
      const Block  w  = apply(Ps, power(apply(Ps, z), -0.5));
      W               = quadratic_representation(power(w, -0.5));
      W_inv           = quadratic_representation(power(w, 0.5));
    }

    static bool
    interior(const Block &x)
    {
      return x[0] > 0. && jdot(x, x) > 0.;
    }

    /// Largest t with x + t d in K_1 (x interior): the first positive root of det(x + t d).
    static double
    max_step(const Block &x, const Block &d)
    {
      const double a = jdot(d, d), b = 2. * jdot(x, d), c = jdot(x, x);
      double       t = std::numeric_limits<double>::infinity();
      if (d[0] < 0.)
        t = -x[0] / d[0];
      if (std::abs(a) <= 1e-14 * (std::abs(b) + std::abs(c)))
        {
          if (b < 0.)
            t = std::min(t, -c / b);
          return t;
        }
      const double disc = b * b - 4. * a * c;
      if (disc < 0.)
        return t;
      const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b)); // stable roots q/a, c/q
      for (const double r : {q / a, q != 0. ? c / q : -1.})
        if (r > 0.)
          t = std::min(t, r);
      return t;
    }
  };
} // namespace granflow::solvers::detail
