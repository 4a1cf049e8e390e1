// Analytic reference solutions of Daviet & Bertails-Descoubes 2016, Section 6.1, in the
// dimensionless variables of (23).
#pragma once

#include <cmath>

namespace granflow::analytic
{
  /// 6.1.1 Bingham Poiseuille flow in y in [-1, 1] driven by a unit body force along x:
  /// u(y) = (Re/2) [(1 - y^2) - 2 Bi (1 - |y|)] for |y| >= Bi, u(Bi) in the plug |y| <= Bi.
  inline double
  bingham_poiseuille_velocity(const double y, const double Bi, const double Re)
  {
    const double a = std::max(std::abs(y), Bi);
    if (Bi >= 1.)
      return 0.;
    return 0.5 * Re * ((1. - a * a) - 2. * Bi * (1. - a));
  }

  /// du/dy of the Bingham Poiseuille profile.
  inline double
  bingham_poiseuille_shear_rate(const double y, const double Bi, const double Re)
  {
    if (std::abs(y) <= Bi)
      return 0.;
    return Re * (Bi * (y > 0 ? 1. : -1.) - y);
  }

  /// 6.1.3 Bagnold profile on a plane inclined at alpha, layer y in [0, 1], eta = |D(u)| = u'/2.
  /// The shear balance of (23), (2 / Re) eta D_xy = (sin a - mu cos a)(1 - y) with u'(1) = 0, gives
  /// u'(y) = sqrt(2 Re (sin a - mu cos a)) (1 - y)^{1/2} and
  /// u = (2/3) sqrt(2 Re (sin a - mu cos a)) (1 - (1 - y)^{3/2}): the paper's formula is Re = 1
  /// (its transcription's sqrt(2 sin a - mu cos a) is read as sqrt(2 (sin a - mu cos a)),
  /// DESIGN.md).
  inline double
  bagnold_shear_rate(const double y, const double mu, const double alpha, const double Re)
  {
    const double c = std::sqrt(2. * Re * (std::sin(alpha) - mu * std::cos(alpha)));
    return c * std::sqrt(std::max(0., 1. - y));
  }

  inline double
  bagnold_velocity(const double y, const double mu, const double alpha, const double Re)
  {
    return 2. / 3. * bagnold_shear_rate(0., mu, alpha, Re) * (1. - std::pow(1. - y, 1.5));
  }
} // namespace granflow::analytic
