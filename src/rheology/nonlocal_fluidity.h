// Nonlocal granular fluidity: the local fluidity g_loc (22) and the cooperativity length xi (24)
// with the smooth parabolic cap of footnote || (Section 4), and their derivatives.
// Henann & Kamrin 2016, Section 2. Pure constitutive code: no mesh, no FE. Physical units (SI).
#pragma once

namespace granflow::rheology
{
  /// Material parameters of the nonlocal rheology (Henann & Kamrin 2016, Section 6 values as
  /// defaults).
  struct NonlocalParameters
  {
    double mu_s          = 0.3819; ///< static yield stress ratio, in (0, 1)
    double b             = 0.9377; ///< rate sensitivity of mu_loc(I) = mu_s + b I, > 0
    double A             = 0.48;   ///< nonlocal amplitude, > 0
    double d             = 1e-3;   ///< grain diameter [m], > 0
    double rho_s         = 2450.;  ///< grain material density [kg/m^3], > 0
    double xi_cap_over_d = 1000.;  ///< cap of xi in grain diameters (footnote ||)
  };

  /// g_loc and its partial derivatives with respect to p and mu.
  struct LocalFluidity
  {
    double value = 0.;
    double d_p   = 0.;
    double d_mu  = 0.;
  };

  /// Henann (22): g_loc = sqrt(p / (rho_s d^2)) (mu - mu_s) / (b mu) if mu > mu_s, else 0.
  /// p <= 0 (no confinement) gives g_loc = 0.
  LocalFluidity
  local_fluidity(double p, double mu, const NonlocalParameters &m);

  /// xi and d xi / d mu.
  struct CooperativityLength
  {
    double value = 0.;
    double d_mu  = 0.;
  };

  /// Henann (24): xi = A d / sqrt|mu - mu_s|, capped smoothly at xi_cap_over_d * d.
  /// For |x| < x_c (x = mu - mu_s) the cap is the parabola xi = a - c x^2 that matches value and
  /// slope of (24) at x_c and has its maximum a = cap at x = 0: x_c = (5 A / (4 cap/d))^2
  /// (3.6e-7 for A = 0.48 and 1000 d, inside the paper's "mu_s +- 1e-6").
  CooperativityLength
  cooperativity_length(double mu, const NonlocalParameters &m);
} // namespace granflow::rheology
