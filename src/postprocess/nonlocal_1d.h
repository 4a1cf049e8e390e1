// Finite-difference reference solutions of the 1D reductions of the nonlocal fluidity model that
// Henann & Kamrin 2016, Section 6.1-6.2, use to verify their elements: linear shear with gravity
// (90) and annular shear without gravity (92), with homogeneous Neumann fluidity conditions at both
// walls, gamma_dot = g mu (20) and v integrated from the fixed far wall. In "force control" (given
// mu_wall) the stress field is known, so (90)/(92) is linear in g; the "_for_speed" variants find
// mu_wall for a prescribed wall speed ("kinematic control", as in the FE runs). Physical units (SI)
// throughout.
#pragma once

#include "rheology/nonlocal_fluidity.h"

#include <vector>

namespace granflow::postprocess
{
  /// Nodal solution of a 1D reduction.
  struct Nonlocal1dProfile
  {
    std::vector<double> x;            ///< z (depth from the driven wall) for (90); r for (92) [m]
    std::vector<double> g;            ///< fluidity [1/s]
    std::vector<double> mu;           ///< stress ratio tau / p
    std::vector<double> p;            ///< pressure [Pa]
    std::vector<double> shear_rate;   ///< gamma_dot = g mu (20) [1/s]
    std::vector<double> v;            ///< velocity, 0 at the far wall [m/s]
    double              mu_wall = 0.; ///< stress ratio at the driven wall
    double              v_wall  = 0.; ///< speed of the driven wall, v at x.front() [m/s]
    /// W: distance from the driven wall at which v = v_wall / e (linear interpolation between
    /// nodes) [m]; NaN when nothing flows (v_wall = 0).
    double shear_band_width = 0.;
  };

  /// W (Henann 6.1): the distance from x.front() at which the nodal profile v, whose value at the
  /// driven wall is v_wall > 0, first falls to v_wall / e, linear between nodes; NaN if it never
  /// does (or v_wall <= 0). The FE runs and the 1D references both measure W with this.
  double
  shear_band_width(const std::vector<double> &x, const std::vector<double> &v, double v_wall);

  /// (90): z in [0, depth], p = P_wall + phi rho_s G z, mu = mu_wall P_wall / p. Defaults are
  /// the paper's case: P_wall / (phi rho_s G d) = 6.67, depth 20 d, step 0.01 d.
  struct LinearShearGravity1d
  {
    rheology::NonlocalParameters material;
    double                       phi    = 0.62;  ///< solid volume fraction, > 0
    double                       G      = 9.81;  ///< gravity [m/s^2], >= 0
    double                       P_wall = 99.39; ///< wall pressure [Pa], > 0
    double                       depth  = 20e-3; ///< bed depth [m], > 0
    double                       h      = 1e-5;  ///< grid step [m], > 0 (reduced to divide depth)
  };

  /// Force control: the profile of (90) for a given wall stress ratio mu_wall >= 0.
  Nonlocal1dProfile
  solve_linear_shear_gravity(const LinearShearGravity1d &problem, double mu_wall);

  /// Kinematic control: the profile of (90) whose wall speed v(0) is v_wall > 0, matched to 1e-13
  /// relative or to the resolution of mu_wall in double (1e-12 near mu_s), whichever is coarser.
  Nonlocal1dProfile
  solve_linear_shear_gravity_for_speed(const LinearShearGravity1d &problem, double v_wall);

  /// The steady state of the paper's own discretization of (90), reduced to 1D: n_elements
  /// linear elements (32)-(35) with 2-point Gauss, z in [0, depth]. At steady state the plastic
  /// shear rate equals the total one at every Gauss point, g_q mu_q = gammadot_e (20), with
  /// gammadot_e constant in the element and g_q interpolated; equilibrium in weak form makes the
  /// Gauss average of tau = mu p the same in every element; the fluidity residual is (34)_2 with
  /// g_loc (22) and xi (24) at the Gauss points, homogeneous Neumann at both ends; the element
  /// shear rates add up to v_wall. Elasticity and finite strain are left out. The FE solution on a
  /// coarse mesh should agree with this, not with the FD solution: it separates the discretization
  /// error of the method (about 0.05 v_wall at h = d) from errors of an implementation.
  /// Solved by Newton (difference Jacobian, backtracking) from `start`, a solution of (90) with
  /// the same data (for example solve_linear_shear_gravity_for_speed); throws if Newton fails.
  /// Returns the nodal profile (x, g, v, and mu, p at the nodes from tau_wall / p).
  Nonlocal1dProfile
  solve_linear_shear_gravity_galerkin(const LinearShearGravity1d &problem, unsigned int n_elements,
                                      double v_wall, const Nonlocal1dProfile &start);

  /// Shear rate of the annular cell. exact: Couette kinematics, gamma_dot = -r d(v/r)/dr, with
  /// omega = v / r = 0 at R_o. paper_dv_dr: gamma_dot = -dv/dr, v(R_o) = 0, as Henann 6.2 has it.
  enum class CouetteKinematics
  {
    exact,
    paper_dv_dr
  };

  /// (92): r in [R_i, R_o], p = P_wall, mu = mu_wall (R_i / r)^2; the inner wall is driven.
  /// Defaults: R_i = 60 d, R_o - R_i = 20 d, step 0.01 d (the paper's case); any P_wall.
  struct AnnularShear1d
  {
    rheology::NonlocalParameters material;
    double                       P_wall = 1000.; ///< wall pressure [Pa], > 0
    double                       R_i    = 60e-3; ///< inner (driven) wall radius [m], > 0
    double                       R_o    = 80e-3; ///< outer (fixed) wall radius [m], > R_i
    double                       h = 1e-5; ///< grid step [m], > 0 (reduced to divide R_o - R_i)
    CouetteKinematics            kinematics = CouetteKinematics::exact;
  };

  /// Force control: the profile of (92) for a given wall stress ratio mu_wall >= 0.
  Nonlocal1dProfile
  solve_annular_shear(const AnnularShear1d &problem, double mu_wall);

  /// Kinematic control: the profile of (92) whose inner wall speed R_i Omega is v_wall > 0 (matched
  /// as in solve_linear_shear_gravity_for_speed).
  Nonlocal1dProfile
  solve_annular_shear_for_speed(const AnnularShear1d &problem, double v_wall);

  /// Operator of the fluidity equation: g'' (cartesian) or (1/r)(r g')' (cylindrical, x = r > 0).
  enum class Coordinates1d
  {
    cartesian,
    cylindrical
  };

  /// Solves L g - g / xi^2 = -g_loc / xi^2 on the uniform grid x (at least 3 nodes, x increasing)
  /// with g' = 0 at both ends: second-order central differences, the cylindrical operator in
  /// conservative form (1/r_i)(r_{i+1/2}(g_{i+1} - g_i) - r_{i-1/2}(g_i - g_{i-1})) / h^2, the
  /// Neumann conditions by mirror ghost nodes, one tridiagonal (Thomas) solve. xi > 0 nodal.
  /// Exposed for the unit tests of the discretisation.
  std::vector<double>
  solve_fluidity_fd(const std::vector<double> &x, const std::vector<double> &xi,
                    const std::vector<double> &g_loc, Coordinates1d coordinates);
} // namespace granflow::postprocess
