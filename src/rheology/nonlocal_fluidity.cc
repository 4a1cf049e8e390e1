#include "rheology/nonlocal_fluidity.h"

#include <cmath>

namespace granflow::rheology
{
  LocalFluidity
  local_fluidity(const double p, const double mu, const NonlocalParameters &m)
  {
    LocalFluidity g;
    if (mu <= m.mu_s || p <= 0.)
      return g;
    // (22): g_loc = s(p) (1 - mu_s / mu) / b with s(p) = sqrt(p / (rho_s d^2)).
    const double s = std::sqrt(p / m.rho_s) / m.d;
    g.value        = s * (1. - m.mu_s / mu) / m.b;
    g.d_p          = 0.5 * g.value / p;
    g.d_mu         = s * m.mu_s / (m.b * mu * mu);
    return g;
  }

  CooperativityLength
  cooperativity_length(const double mu, const NonlocalParameters &m)
  {
    CooperativityLength xi;
    const double        x   = mu - m.mu_s;
    const double        ax  = std::abs(x);
    const double        Ad  = m.A * m.d;
    const double        cap = m.xi_cap_over_d * m.d;
    const double        x_c = std::pow(1.25 * Ad / cap, 2);
    if (ax >= x_c)
      {
        // (24)
        xi.value = Ad / std::sqrt(ax);
        xi.d_mu  = -0.5 * xi.value / x; // d/dx |x|^{-1/2} = -sign(x) |x|^{-3/2} / 2
      }
    else
      {
        // Parabolic cap: a = (5/4) A d x_c^{-1/2} = cap, c = (1/4) A d x_c^{-5/2}.
        const double c = 0.25 * Ad * std::pow(x_c, -2.5);
        xi.value       = cap - c * x * x;
        xi.d_mu        = -2. * c * x;
      }
    return xi;
  }
} // namespace granflow::rheology
