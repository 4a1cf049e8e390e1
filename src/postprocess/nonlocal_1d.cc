#include "postprocess/nonlocal_1d.h"
#include "solvers/dense.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace granflow::postprocess
{
  namespace
  {
    void
    require(const bool condition, const std::string &message)
    {
      if (!condition)
        throw std::invalid_argument(message);
    }

    void
    check_material(const rheology::NonlocalParameters &m, const std::string &where)
    {
      // Written as !(a > b) so that NaN inputs are rejected too.
      require(m.mu_s > 0. && m.mu_s < 1., where + ": mu_s must be in (0, 1)");
      require(m.b > 0., where + ": b must be > 0");
      require(m.A > 0., where + ": A must be > 0");
      require(m.d > 0., where + ": grain diameter d must be > 0");
      require(m.rho_s > 0., where + ": rho_s must be > 0");
      require(m.xi_cap_over_d > 0., where + ": xi_cap_over_d must be > 0");
    }

    // Uniform grid on [a, b] with a step <= h: an integer number of intervals (at least 2) keeps
    // both walls on nodes, which the Neumann ghost nodes and the v = 0 condition need.
    std::vector<double>
    uniform_grid(const double a, const double b, const double h)
    {
      const double length = b - a;
      const auto   n = static_cast<std::size_t>(std::max(2., std::ceil(length / h * (1. - 1e-12))));
      std::vector<double> x(n + 1);
      for (std::size_t i = 0; i <= n; ++i)
        x[i] = a + length * double(i) / double(n);
      x[n] = b;
      return x;
    }

    /// The data of (90) that every solver of it needs.
    void
    check_linear_shear(const LinearShearGravity1d &problem, const std::string &where)
    {
      check_material(problem.material, where);
      require(problem.phi > 0., where + ": phi must be > 0");
      require(problem.G >= 0., where + ": G must be >= 0");
      require(problem.P_wall > 0., where + ": P_wall must be > 0");
      require(problem.depth > 0., where + ": depth must be > 0");
    }

    /// (90): p = P_wall + phi rho_s G z at depth z.
    double
    linear_shear_pressure(const LinearShearGravity1d &problem, const double z)
    {
      return problem.P_wall + problem.phi * problem.material.rho_s * problem.G * z;
    }

    void
    set_shear_band_width(Nonlocal1dProfile &profile)
    {
      profile.shear_band_width = shear_band_width(profile.x, profile.v, profile.v_wall);
    }

    // Fills g (linear solve of (90)/(92) for the known mu, p), gamma_dot = g mu (20), v and W.
    // The velocity comes from the far wall (v = 0) by the trapezoidal rule on dv/dx = -gamma_dot
    // (cartesian, paper_dv_dr) or, for exact Couette kinematics, on d omega/dr = -gamma_dot / r
    // with omega(R_o) = 0 and v = r omega.
    void
    complete_profile(Nonlocal1dProfile &profile, const rheology::NonlocalParameters &m,
                     const Coordinates1d coordinates, const bool couette_omega)
    {
      const std::size_t   n = profile.x.size();
      std::vector<double> xi(n), g_loc(n);
      for (std::size_t i = 0; i < n; ++i)
        {
          xi[i]    = rheology::cooperativity_length(profile.mu[i], m).value;
          g_loc[i] = rheology::local_fluidity(profile.p[i], profile.mu[i], m).value;
        }
      profile.g = solve_fluidity_fd(profile.x, xi, g_loc, coordinates);

      profile.shear_rate.resize(n);
      for (std::size_t i = 0; i < n; ++i)
        profile.shear_rate[i] = profile.g[i] * profile.mu[i];

      profile.v.assign(n, 0.);
      const auto &x = profile.x;
      if (couette_omega)
        {
          double omega = 0.;
          for (std::size_t i = n - 1; i-- > 0;)
            {
              omega += 0.5 * (x[i + 1] - x[i]) *
                       (profile.shear_rate[i] / x[i] + profile.shear_rate[i + 1] / x[i + 1]);
              profile.v[i] = x[i] * omega;
            }
        }
      else
        for (std::size_t i = n - 1; i-- > 0;)
          profile.v[i] = profile.v[i + 1] + 0.5 * (x[i + 1] - x[i]) *
                                                (profile.shear_rate[i] + profile.shear_rate[i + 1]);

      profile.v_wall = profile.v.front();
      // v decreases monotonically from the driven wall (g >= 0: the discrete operator is an
      // M-matrix and g_loc >= 0), so the first crossing of v_wall / e is the only one.
      set_shear_band_width(profile);
    }

    // mu_wall such that v_wall(mu_wall) = target. v_wall is 0 for mu_wall <= mu_s and grows like a
    // power of mu_wall - mu_s (about the cube) near mu_s and about linearly far above it, so the
    // root is bracketed and refined in s = log(mu_wall - mu_s), where log v_wall is close to linear
    // in both regimes: Illinois (regula falsi with halving of the stagnant end), bisection when an
    // end is -inf.
    Nonlocal1dProfile
    find_mu_wall(const std::function<Nonlocal1dProfile(double)> &solve, const double mu_s,
                 const double target, const std::string &where)
    {
      require(target > 0. && std::isfinite(target), where + ": target wall speed must be > 0");
      const double log_target = std::log(target);

      Nonlocal1dProfile best;
      double            best_residual = std::numeric_limits<double>::infinity();
      // log v_wall - log target, -inf when nothing flows; keeps the best profile seen.
      auto f = [&](const double s) {
        Nonlocal1dProfile profile  = solve(mu_s + std::exp(s));
        double            residual = -std::numeric_limits<double>::infinity();
        if (profile.v_wall > 0.)
          residual = std::log(profile.v_wall) - log_target;
        if (std::abs(residual) < best_residual)
          {
            best_residual = std::abs(residual);
            best          = std::move(profile);
          }
        return residual;
      };

      // Bracket: s_hi with f >= 0 (doubling mu_wall - mu_s), s_lo with f < 0 (dividing by 10).
      const double max_excess = 1e6;
      const double min_excess = 1e-15 * mu_s;
      double       s_lo = 0., f_lo = 0.;
      double       s_hi = std::log(0.1), f_hi = f(s_hi);
      bool         have_lo = false;
      while (f_hi < 0.)
        {
          s_lo    = s_hi;
          f_lo    = f_hi;
          have_lo = true;
          s_hi += std::log(2.);
          if (std::exp(s_hi) > max_excess)
            throw std::runtime_error(where + ": no mu_wall - mu_s <= 1e6 reaches the target speed");
          f_hi = f(s_hi);
        }
      while (!have_lo)
        {
          s_lo = s_hi - std::log(10.);
          if (std::exp(s_lo) < min_excess)
            throw std::runtime_error(where +
                                     ": target speed below what mu_wall - mu_s >= 1e-15 mu_s "
                                     "resolves");
          f_lo = f(s_lo);
          if (f_lo < 0.)
            have_lo = true;
          else
            {
              s_hi = s_lo;
              f_hi = f_lo;
            }
        }

      // Stop at 1e-13 in log v_wall or when the bracket no longer changes mu_wall in double.
      const double tolerance = 1e-13;
      int          side      = 0;
      for (int it = 0; it < 200 && best_residual > tolerance; ++it)
        {
          if (mu_s + std::exp(s_lo) == mu_s + std::exp(s_hi))
            break;
          double s;
          if (std::isfinite(f_lo) && f_hi > f_lo)
            s = s_hi - f_hi * (s_hi - s_lo) / (f_hi - f_lo);
          else
            s = 0.5 * (s_lo + s_hi);
          if (!(s > s_lo && s < s_hi))
            s = 0.5 * (s_lo + s_hi);
          const double f_s = f(s);
          if (f_s < 0.)
            {
              s_lo = s;
              f_lo = f_s;
              if (side == -1)
                f_hi *= 0.5;
              side = -1;
            }
          else
            {
              s_hi = s;
              f_hi = f_s;
              if (side == 1 && std::isfinite(f_lo))
                f_lo *= 0.5;
              side = 1;
            }
        }
      return best;
    }
  } // namespace

  double
  shear_band_width(const std::vector<double> &x, const std::vector<double> &v, const double v_wall)
  {
    if (!(v_wall > 0.))
      return std::numeric_limits<double>::quiet_NaN();
    const double v_e = v_wall * std::exp(-1.);
    for (std::size_t i = 1; i < x.size() && i < v.size(); ++i)
      if (v[i] <= v_e && v[i - 1] > v_e)
        return x[i - 1] + (x[i] - x[i - 1]) * (v[i - 1] - v_e) / (v[i - 1] - v[i]) - x.front();
    return std::numeric_limits<double>::quiet_NaN();
  }

  std::vector<double>
  solve_fluidity_fd(const std::vector<double> &x, const std::vector<double> &xi,
                    const std::vector<double> &g_loc, const Coordinates1d coordinates)
  {
    const std::size_t n = x.size();
    require(n >= 3, "solve_fluidity_fd: at least 3 nodes needed");
    require(xi.size() == n && g_loc.size() == n,
            "solve_fluidity_fd: x, xi and g_loc must have the same size");
    const double h = (x.back() - x.front()) / double(n - 1);
    require(h > 0., "solve_fluidity_fd: x must be increasing");
    // (with the rounding of x itself: at R_i = 1e5 d the grid of 0.01 d lies 1e7 spacings from 0)
    for (std::size_t i = 0; i + 1 < n; ++i)
      require(std::abs(x[i + 1] - x[i] - h) <=
                  1e-9 * h + 16. * std::numeric_limits<double>::epsilon() * std::abs(x[i + 1]),
              "solve_fluidity_fd: x must be uniform");
    require(coordinates == Coordinates1d::cartesian || x.front() > 0.,
            "solve_fluidity_fd: cylindrical coordinates need r > 0");
    for (std::size_t i = 0; i < n; ++i)
      require(xi[i] > 0. && std::isfinite(g_loc[i]),
              "solve_fluidity_fd: xi must be > 0 and g_loc finite");

    // Row i times -h^2: -lower g_{i-1} + diag g_i - upper g_{i+1} = h^2 g_loc / xi^2, with
    // diag = lower + upper + h^2 / xi^2. At the ends the mirror ghost (g_{-1} = g_1, g' = 0)
    // doubles the one neighbour coupling; in the cylindrical operator r_{1/2} + r_{-1/2} = 2 r_0
    // gives the same factor 2.
    std::vector<double> lower(n), diag(n), upper(n), rhs(n);
    for (std::size_t i = 0; i < n; ++i)
      {
        double w_minus = 1., w_plus = 1.;
        if (coordinates == Coordinates1d::cylindrical)
          {
            w_minus = (x[i] - 0.5 * h) / x[i];
            w_plus  = (x[i] + 0.5 * h) / x[i];
          }
        if (i == 0)
          w_minus = 0., w_plus = 2.;
        else if (i == n - 1)
          w_minus = 2., w_plus = 0.;
        const double e = h * h / (xi[i] * xi[i]);
        lower[i]       = w_minus;
        upper[i]       = w_plus;
        diag[i]        = w_minus + w_plus + e;
        rhs[i]         = e * g_loc[i];
      }

    // Thomas: the matrix is a diagonally dominant M-matrix, so no pivoting is needed and the
    // pivots stay positive.
    std::vector<double> c(n), g(n);
    double              pivot = diag[0];
    c[0]                      = -upper[0] / pivot;
    g[0]                      = rhs[0] / pivot;
    for (std::size_t i = 1; i < n; ++i)
      {
        pivot = diag[i] + lower[i] * c[i - 1];
        c[i]  = -upper[i] / pivot;
        g[i]  = (rhs[i] + lower[i] * g[i - 1]) / pivot;
      }
    for (std::size_t i = n - 1; i-- > 0;)
      g[i] -= c[i] * g[i + 1];
    return g;
  }

  Nonlocal1dProfile
  solve_linear_shear_gravity(const LinearShearGravity1d &problem, const double mu_wall)
  {
    const std::string where = "linear shear with gravity (Henann 90)";
    check_linear_shear(problem, where);
    require(problem.h > 0., where + ": grid step h must be > 0");
    require(problem.h <= 0.5 * problem.depth, where + ": grid step h must be <= depth / 2");
    require(mu_wall >= 0. && std::isfinite(mu_wall), where + ": mu_wall must be >= 0");

    Nonlocal1dProfile profile;
    profile.mu_wall = mu_wall;
    profile.x       = uniform_grid(0., problem.depth, problem.h);
    for (const double z : profile.x)
      {
        // (90)_2,3: tau = mu_wall P_wall everywhere, p grows with the weight of the grains above.
        profile.p.push_back(linear_shear_pressure(problem, z));
        profile.mu.push_back(mu_wall * problem.P_wall / profile.p.back());
      }
    complete_profile(profile, problem.material, Coordinates1d::cartesian, false);
    return profile;
  }

  Nonlocal1dProfile
  solve_linear_shear_gravity_for_speed(const LinearShearGravity1d &problem, const double v_wall)
  {
    return find_mu_wall(
        [&](const double mu_wall) { return solve_linear_shear_gravity(problem, mu_wall); },
        problem.material.mu_s, v_wall, "linear shear with gravity (Henann 90)");
  }

  Nonlocal1dProfile
  solve_linear_shear_gravity_galerkin(const LinearShearGravity1d &problem,
                                      const unsigned int n_elements, const double v_wall,
                                      const Nonlocal1dProfile &start)
  {
    const std::string where = "Galerkin reduction of linear shear with gravity (Henann 34, 90)";
    check_linear_shear(problem, where);
    require(n_elements >= 2, where + ": at least 2 elements needed");
    require(v_wall > 0., where + ": v_wall must be > 0");
    require(start.x.size() >= 2 && start.mu_wall > problem.material.mu_s,
            where + ": the start must be a flowing solution of (90)");
    const auto  &m           = problem.material;
    const auto   N           = n_elements;
    const double h           = problem.depth / N;
    const double gauss[2]    = {0.5 - 0.5 / std::sqrt(3.), 0.5 + 0.5 / std::sqrt(3.)}; // in [0, 1]
    const auto   pressure    = [&](const double z) { return linear_shear_pressure(problem, z); };
    const auto   interpolate = [](const std::vector<double> &x, const std::vector<double> &y,
                                const double at) {
      const auto k =
          std::min<std::size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin(), x.size() - 1);
      const std::size_t i = k == 0 ? 0 : k - 1;
      const double      t = (at - x[i]) / (x[i + 1] - x[i]);
      return (1. - t) * y[i] + t * y[i + 1];
    };

    // Unknowns: the nodal g (scaled by g_scale) and mu_wall = tau_wall / P_wall.
    const double        g_scale = start.g.front();
    std::vector<double> x(N + 2);
    for (unsigned int a = 0; a <= N; ++a)
      x[a] = interpolate(start.x, start.g, a * h) / g_scale;
    x[N + 1] = start.mu_wall;

    // Element shear rate: mu_q = gammadot / g_q and (mu_1 p_1 + mu_2 p_2) / 2 = tau_wall.
    const auto element_rate = [&](const std::vector<double> &y, const unsigned int e, double g_q[2],
                                  double p_q[2]) {
      for (unsigned int q = 0; q < 2; ++q)
        {
          g_q[q] = std::max(g_scale * ((1. - gauss[q]) * y[e] + gauss[q] * y[e + 1]), 1e-300);
          p_q[q] = pressure((e + gauss[q]) * h);
        }
      return 2. * y[N + 1] * problem.P_wall / (p_q[0] / g_q[0] + p_q[1] / g_q[1]);
    };
    // (34)_2 per node (scaled by h / g_scale) and the wall speed (scaled by 1 / v_wall).
    const auto residual = [&](const std::vector<double> &y) {
      std::vector<double> r(N + 2, 0.);
      double              speed = 0.;
      for (unsigned int e = 0; e < N; ++e)
        {
          double       g_q[2], p_q[2];
          const double rate = element_rate(y, e, g_q, p_q);
          speed += rate * h;
          const double slope = g_scale * (y[e + 1] - y[e]) / h;
          r[e] -= slope;
          r[e + 1] += slope;
          for (unsigned int q = 0; q < 2; ++q)
            {
              const double mu = rate / g_q[q];
              const double xi = rheology::cooperativity_length(mu, m).value;
              const double f = (g_q[q] - rheology::local_fluidity(p_q[q], mu, m).value) / (xi * xi);
              r[e] += 0.5 * h * (1. - gauss[q]) * f;
              r[e + 1] += 0.5 * h * gauss[q] * f;
            }
        }
      for (unsigned int a = 0; a <= N; ++a)
        r[a] *= h / g_scale;
      r[N + 1] = speed / v_wall - 1.;
      return r;
    };
    const auto norm = [](const std::vector<double> &r) {
      double s = 0.;
      for (const double v : r)
        s += v * v;
      return std::sqrt(s);
    };

    std::vector<double> r = residual(x);
    for (unsigned int it = 0; norm(r) > 1e-12; ++it)
      {
        require(it < 50, where + ": Newton did not converge");
        // Jacobian by central differences, then Gaussian elimination with partial pivoting.
        const std::size_t                n = x.size();
        std::vector<std::vector<double>> J(n, std::vector<double>(n + 1));
        for (std::size_t j = 0; j < n; ++j)
          {
            const double        step = 1e-7 * std::max(std::abs(x[j]), 1e-3);
            std::vector<double> xp = x, xm = x;
            xp[j] += step;
            xm[j] -= step;
            const auto rp = residual(xp), rm = residual(xm);
            for (std::size_t i = 0; i < n; ++i)
              J[i][j] = (rp[i] - rm[i]) / (2. * step);
          }
        for (std::size_t i = 0; i < n; ++i)
          J[i][n] = -r[i];
        std::vector<double> dx;
        require(solvers::solve_augmented(J, dx), where + ": singular Jacobian");
        double t = 1.;
        for (;; t *= 0.5)
          {
            require(t > 1e-6, where + ": no descent along the Newton step");
            std::vector<double> trial = x;
            for (std::size_t i = 0; i < n; ++i)
              trial[i] += t * dx[i];
            const auto r_trial = residual(trial);
            if (norm(r_trial) < (1. - 1e-4 * t) * norm(r))
              {
                x = trial;
                r = r_trial;
                break;
              }
          }
      }

    Nonlocal1dProfile profile;
    profile.mu_wall = x[N + 1];
    profile.v.assign(N + 1, 0.);
    for (unsigned int e = N; e-- > 0;)
      {
        double g_q[2], p_q[2];
        profile.v[e] = profile.v[e + 1] + element_rate(x, e, g_q, p_q) * h;
      }
    for (unsigned int a = 0; a <= N; ++a)
      {
        profile.x.push_back(a * h);
        profile.g.push_back(g_scale * x[a]);
        profile.p.push_back(pressure(a * h));
        profile.mu.push_back(profile.mu_wall * problem.P_wall / profile.p.back());
      }
    profile.v_wall = profile.v.front();
    set_shear_band_width(profile);
    return profile;
  }

  Nonlocal1dProfile
  solve_annular_shear(const AnnularShear1d &problem, const double mu_wall)
  {
    const std::string where = "annular shear (Henann 92)";
    check_material(problem.material, where);
    require(problem.P_wall > 0., where + ": P_wall must be > 0");
    require(problem.R_i > 0., where + ": R_i must be > 0");
    require(problem.R_o > problem.R_i, where + ": R_o must be > R_i");
    require(problem.h > 0., where + ": grid step h must be > 0");
    require(problem.h <= 0.5 * (problem.R_o - problem.R_i),
            where + ": grid step h must be <= (R_o - R_i) / 2");
    require(mu_wall >= 0. && std::isfinite(mu_wall), where + ": mu_wall must be >= 0");

    Nonlocal1dProfile profile;
    profile.mu_wall = mu_wall;
    profile.x       = uniform_grid(problem.R_i, problem.R_o, problem.h);
    for (const double r : profile.x)
      {
        // (92)_2,3: the moment balance gives tau = tau_wall (R_i / r)^2 at constant pressure.
        profile.p.push_back(problem.P_wall);
        profile.mu.push_back(mu_wall * (problem.R_i / r) * (problem.R_i / r));
      }
    complete_profile(profile, problem.material, Coordinates1d::cylindrical,
                     problem.kinematics == CouetteKinematics::exact);
    return profile;
  }

  Nonlocal1dProfile
  solve_annular_shear_for_speed(const AnnularShear1d &problem, const double v_wall)
  {
    return find_mu_wall([&](const double mu_wall) { return solve_annular_shear(problem, mu_wall); },
                        problem.material.mu_s, v_wall, "annular shear (Henann 92)");
  }
} // namespace granflow::postprocess
