// Drucker-Prager rheology DP(mu, Bi) on R^{s(d)}: the orthonormal map chi, second-order cones,
// projections, and the Alart-Curnier, De Saxce and Fischer-Burmeister residuals.
// Daviet & Bertails-Descoubes 2016, Section 3.2: Definition 1 (chi), Properties 1-2, (7), (16),
// Definition 2 (f_AC), (17), Definition 3 (f_DS), Theorems 1-3; FB from Daviet et al. 2011.
// Pure constitutive code: no mesh, no FE.
#pragma once

#include <deal.II/base/symmetric_tensor.h>

#include <array>
#include <cmath>

namespace granflow::rheology
{
  /// s(d) = dim S_d = d(d+1)/2.
  template <int dim>
  constexpr unsigned int n_sym = dim * (dim + 1) / 2;

  /// A symmetric tensor in the chi-coordinates of Definition 1: component 0 is the normal part
  /// x_N = Tr / sqrt(2d) (12a), components 1.. are the tangential part x_T with |Dev| = ||x_T|| (12b).
  template <int dim>
  using SymVector = std::array<double, n_sym<dim>>;

  /// Daviet Definition 1: chi(a; b, c, ...) in S_d. Orthonormal for <s, t> = s:t / 2 (Property 1).
  template <int dim>
  dealii::SymmetricTensor<2, dim>
  chi(const SymVector<dim> &x);

  /// chi^{-1}: components are <chi(e_j), sigma> = chi(e_j) : sigma / 2.
  template <int dim>
  SymVector<dim>
  chi_inverse(const dealii::SymmetricTensor<2, dim> &sigma);

  /// Daviet Section 2: <sigma, tau> = sigma : tau / 2 and |sigma| = sqrt(<sigma, sigma>).
  template <int dim>
  double
  tensor_norm(const dealii::SymmetricTensor<2, dim> &sigma)
  {
    return std::sqrt(0.5 * (sigma * sigma));
  }

  /// ||x_T||, the Euclidean norm of the tangential part.
  template <std::size_t n>
  double
  norm_T(const std::array<double, n> &x)
  {
    double s = 0.;
    for (std::size_t i = 1; i < n; ++i)
      s += x[i] * x[i];
    return std::sqrt(s);
  }

  /// Orthogonal projection onto the second-order cone K_mu = {||x_T|| <= mu x_N} (7), mu >= 0.
  /// K_0 is the ray {x_T = 0, x_N >= 0}, i.e. (16) with Bi = 0, not the whole x_N axis of (7).
  template <std::size_t n>
  std::array<double, n>
  project_onto_cone(const std::array<double, n> &x, double mu);

  /// Orthogonal projection onto the truncated cone K_{mu,Bi} = {x_N >= 0, ||x_T|| <= Bi + mu x_N} (16).
  /// Four cases (proof of Theorem 3): interior, conical face, base disc x_N = 0, circular edge.
  template <std::size_t n>
  std::array<double, n>
  project_onto_truncated_cone(const std::array<double, n> &x, double mu, double Bi);

  /// De Saxce change of variable (17): gamma_hat = (gamma_N + mu ||gamma_T||; gamma_T).
  template <std::size_t n>
  std::array<double, n>
  de_saxce(const std::array<double, n> &gamma, double mu);

  /// Daviet Definition 2: extended Alart-Curnier function f_AC(lambda, gamma), zero iff DP(mu, Bi) holds.
  template <std::size_t n>
  std::array<double, n>
  f_AC(const std::array<double, n> &lambda,
       const std::array<double, n> &gamma,
       double                       mu,
       double                       Bi,
       double                       xi_N = 1.,
       double                       xi_T = 1.);

  /// Daviet Definition 3 (18): f_DS(lambda, gamma) = Pi_{K_{mu,Bi}}(lambda - xi gamma_hat) - lambda.
  template <std::size_t n>
  std::array<double, n>
  f_DS(const std::array<double, n> &lambda,
       const std::array<double, n> &gamma,
       double                       mu,
       double                       Bi,
       double                       xi = 1.);

  /// Fischer-Burmeister function of the unit second-order cone K_1 in its Jordan algebra:
  /// phi(x, y) = x + y - sqrt(x o x + y o y); zero iff K_1 \ni x _|_ y \in K_1.
  template <std::size_t n>
  std::array<double, n>
  fischer_burmeister_K1(const std::array<double, n> &x, const std::array<double, n> &y);

  /// SOC Fischer-Burmeister residual of DP(mu, 0) (Corollary 1, Daviet et al. 2011): the cones
  /// K_mu \ni lambda _|_ gamma_hat \in K_{1/mu} mapped onto K_1 by x = (mu lambda_N; lambda_T),
  /// y = (gamma_hat_N; mu gamma_hat_T). For mu = 0 (K_0 is a ray, its dual a half-space) it is the
  /// scalar FB function of (lambda_N, gamma_N) followed by lambda_T.
  template <std::size_t n>
  std::array<double, n>
  f_FB(const std::array<double, n> &lambda, const std::array<double, n> &gamma, double mu);

  /// Euclidean norm of a small vector.
  template <std::size_t n>
  double
  norm(const std::array<double, n> &x)
  {
    double s = 0.;
    for (const double v : x)
      s += v * v;
    return std::sqrt(s);
  }
} // namespace granflow::rheology
