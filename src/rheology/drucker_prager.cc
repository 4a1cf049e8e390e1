// Daviet & Bertails-Descoubes 2016, Section 3.2 and Appendix A; see drucker_prager.h.
#include "rheology/drucker_prager.h"

#include <algorithm>

namespace granflow::rheology
{
  template <>
  dealii::SymmetricTensor<2, 2>
  chi<2>(const SymVector<2> &x)
  {
    // Definition 1, d = 2: chi(a; b, c) = [[b, c], [c, -b]] + a I.
    dealii::SymmetricTensor<2, 2> s;
    s[0][0] = x[1] + x[0];
    s[1][1] = -x[1] + x[0];
    s[0][1] = x[2];
    return s;
  }

  template <>
  dealii::SymmetricTensor<2, 3>
  chi<3>(const SymVector<3> &x)
  {
    // Definition 1, d = 3.
    const double r3 = std::sqrt(3.), a = std::sqrt(2. / 3.) * x[0];
    dealii::SymmetricTensor<2, 3> s;
    s[0][0] = x[1] - x[2] / r3 + a;
    s[1][1] = -x[1] - x[2] / r3 + a;
    s[2][2] = 2. * x[2] / r3 + a;
    s[0][1] = x[3];
    s[0][2] = x[4];
    s[1][2] = x[5];
    return s;
  }

  template <int dim>
  SymVector<dim>
  chi_inverse(const dealii::SymmetricTensor<2, dim> &sigma)
  {
    // chi is orthonormal (Property 1), so x_j = <chi(e_j), sigma> = chi(e_j) : sigma / 2.
    SymVector<dim> x{};
    for (unsigned int j = 0; j < n_sym<dim>; ++j)
      {
        SymVector<dim> e{};
        e[j] = 1.;
        x[j] = 0.5 * (chi<dim>(e) * sigma);
      }
    return x;
  }

  template <std::size_t n>
  std::array<double, n>
  project_onto_cone(const std::array<double, n> &x, const double mu)
  {
    const double t = norm_T(x);
    if (x[0] >= 0. && t <= mu * x[0]) // x_N >= 0: for mu = 0, K_0 is the ray, not the x_N axis
      return x;
    std::array<double, n> p{};
    if (mu * t <= -x[0])
      return p;
    // Closest point on the boundary ray spanned by (1, mu x_T / t).
    const double alpha = (x[0] + mu * t) / (1. + mu * mu);
    p[0]               = alpha;
    if (t > 0.)
      for (std::size_t i = 1; i < n; ++i)
        p[i] = mu * alpha * x[i] / t;
    return p;
  }

  template <std::size_t n>
  std::array<double, n>
  project_onto_truncated_cone(const std::array<double, n> &x, const double mu, const double Bi)
  {
    if (Bi == 0.)
      return project_onto_cone(x, mu);
    const double t = norm_T(x);
    if (x[0] >= 0. && t <= Bi + mu * x[0])
      return x; // interior
    std::array<double, n> p = x;
    if (x[0] < 0. && t <= Bi)
      {
        p[0] = 0.; // base disc
        return p;
      }
    // Here ||x_T|| > Bi + mu max(x_N, 0) >= Bi > 0. In the half-plane (x_N, ||x_T||), s is the foot
    // of x on the face line r = Bi + mu s: s > 0 is the conical face, s <= 0 the circular edge
    // (0; Bi x_T / ||x_T||); mu = 0 is the cylinder. Computed without shifting the apex to -Bi/mu,
    // which would lose log10(Bi / (mu |x|)) digits for small mu.
    const double s = std::max(0., (x[0] + mu * (t - Bi)) / (1. + mu * mu));
    const double r = Bi + mu * s;
    p[0]           = s;
    for (std::size_t i = 1; i < n; ++i)
      p[i] = x[i] * r / t;
    return p;
  }

  template <std::size_t n>
  std::array<double, n>
  de_saxce(const std::array<double, n> &gamma, const double mu)
  {
    std::array<double, n> g = gamma;
    g[0] += mu * norm_T(gamma);
    return g;
  }

  template <std::size_t n>
  std::array<double, n>
  f_AC(const std::array<double, n> &lambda,
       const std::array<double, n> &gamma,
       const double                 mu,
       const double                 Bi,
       const double                 xi_N,
       const double                 xi_T)
  {
    std::array<double, n> f{};
    f[0] = std::max(0., lambda[0] - xi_N * gamma[0]) - lambda[0];
    // Ball of radius kappa(lambda_N) = Bi + mu lambda_N (empty radius clipped at zero).
    const double radius = std::max(0., Bi + mu * lambda[0]);
    std::array<double, n> y{};
    for (std::size_t i = 1; i < n; ++i)
      y[i] = lambda[i] - xi_T * gamma[i];
    const double ty    = norm_T(y);
    const double scale = ty > radius ? radius / ty : 1.;
    for (std::size_t i = 1; i < n; ++i)
      f[i] = scale * y[i] - lambda[i];
    return f;
  }

  template <std::size_t n>
  std::array<double, n>
  f_DS(const std::array<double, n> &lambda,
       const std::array<double, n> &gamma,
       const double                 mu,
       const double                 Bi,
       const double                 xi)
  {
    const std::array<double, n> g_hat = de_saxce(gamma, mu);
    std::array<double, n>       y{};
    for (std::size_t i = 0; i < n; ++i)
      y[i] = lambda[i] - xi * g_hat[i];
    std::array<double, n> f = project_onto_truncated_cone(y, mu, Bi);
    for (std::size_t i = 0; i < n; ++i)
      f[i] -= lambda[i];
    return f;
  }

  namespace
  {
    /// det(x) = x_0^2 - ||x_T||^2, the product of the spectral values x_0 -+ ||x_T||.
    template <std::size_t n>
    double
    soc_det(const std::array<double, n> &x)
    {
      const double t = norm_T(x);
      return (x[0] - t) * (x[0] + t);
    }
  } // namespace

  template <std::size_t n>
  std::array<double, n>
  fischer_burmeister_K1(const std::array<double, n> &x, const std::array<double, n> &y)
  {
    // z = x o x + y o y = (|x|^2 + |y|^2; 2 (x_0 x_T + y_0 y_T)) has spectral values
    // l_{1,2} = z_0 -+ ||z_T||, and sqrt(z) = ((s1 + s2)/2; z_T/(s1 + s2)) with s_i = sqrt(l_i).
    // At a solution l1 is 0 or small, where z_0 - ||z_T|| cancels and would leave a residual of
    // O(sqrt(eps) |z|^(1/2)) instead of O(eps). Hence l1 = det(z)/l2, with
    // det(z) = det(x)^2 + det(y)^2 + 2 <x o x, y o y>_J (det is the quadratic form of
    // <a, b>_J = a_0 b_0 - a_T.b_T), a sum of terms that are >= 0.
    double xx = 0., yy = 0., xTyT = 0.;
    for (std::size_t i = 0; i < n; ++i)
      {
        xx += x[i] * x[i];
        yy += y[i] * y[i];
      }
    for (std::size_t i = 1; i < n; ++i)
      xTyT += x[i] * y[i];
    std::array<double, n> z{};
    z[0] = xx + yy;
    for (std::size_t i = 1; i < n; ++i)
      z[i] = 2. * (x[0] * x[i] + y[0] * y[i]);
    const double dx = soc_det(x), dy = soc_det(y);
    const double det = dx * dx + dy * dy + 2. * std::max(0., xx * yy - 4. * x[0] * y[0] * xTyT);
    const double l2  = z[0] + norm_T(z);
    const double s2  = std::sqrt(l2);
    const double s1  = l2 > 0. ? std::sqrt(det / l2) : 0.;
    std::array<double, n> f{};
    if (s1 + s2 == 0.)
      return f; // x = y = 0
    f[0] = x[0] + y[0] - 0.5 * (s1 + s2);
    for (std::size_t i = 1; i < n; ++i)
      f[i] = x[i] + y[i] - z[i] / (s1 + s2);
    return f;
  }

  template <std::size_t n>
  std::array<double, n>
  f_FB(const std::array<double, n> &lambda, const std::array<double, n> &gamma, const double mu)
  {
    if (mu == 0.)
      {
        std::array<double, n> f = lambda;
        f[0] = lambda[0] + gamma[0] - std::hypot(lambda[0], gamma[0]);
        return f;
      }
    const std::array<double, n> g_hat = de_saxce(gamma, mu);
    std::array<double, n>       x = lambda, y = g_hat;
    x[0] *= mu;
    for (std::size_t i = 1; i < n; ++i)
      y[i] *= mu;
    return fischer_burmeister_K1(x, y);
  }

  template dealii::SymmetricTensor<2, 2> chi<2>(const SymVector<2> &);
  template dealii::SymmetricTensor<2, 3> chi<3>(const SymVector<3> &);
  template SymVector<2> chi_inverse<2>(const dealii::SymmetricTensor<2, 2> &);
  template SymVector<3> chi_inverse<3>(const dealii::SymmetricTensor<2, 3> &);

#define GRANFLOW_INSTANTIATE(n)                                                                    \
  template std::array<double, n> project_onto_cone(const std::array<double, n> &, double);        \
  template std::array<double, n> project_onto_truncated_cone(const std::array<double, n> &,       \
                                                             double,                               \
                                                             double);                              \
  template std::array<double, n> de_saxce(const std::array<double, n> &, double);                 \
  template std::array<double, n> f_AC(                                                             \
    const std::array<double, n> &, const std::array<double, n> &, double, double, double, double); \
  template std::array<double, n> f_DS(                                                             \
    const std::array<double, n> &, const std::array<double, n> &, double, double, double);         \
  template std::array<double, n> fischer_burmeister_K1(const std::array<double, n> &,             \
                                                       const std::array<double, n> &);             \
  template std::array<double, n> f_FB(const std::array<double, n> &,                              \
                                      const std::array<double, n> &,                              \
                                      double);
  GRANFLOW_INSTANTIATE(3)
  GRANFLOW_INSTANTIATE(6)
#undef GRANFLOW_INSTANTIATE
} // namespace granflow::rheology
