// ngf: the increments to steady state (Section 6), steadiness, the run's warnings and failures, and
// ngf::run().
#include "models/ngf/ngf_problem.h"

#include "core/format_number.h"
#include "core/interrupt.h"
#include "core/max_abs.h"
#include "core/time_left.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

namespace granflow::ngf::detail
{
  template <int dim>
  double
  Problem<dim>::wall_stress_ratio() const
  {
    // Column: the x-force of the wall on the bed per unit area over P_wall. Annulus: the moment
    // of the inner wall per radian, M = tau_wall R_i (R_i H), over R_i^2 H P (P_wall, or for 6.3
    // the mean hydrostatic pressure along the wall, phi rho_s G H / 2).
    if (slice)
      {
        // the moment about z of the wall's x- and y-reactions at the nodes' current positions
        // (the radial reactions have a lever arm once the wall has turned), per radian of the
        // slice; the dofs of a node are numbered together, x before y (checked in
        // setup_system())
        double moment = 0.;
        for (const auto i :
             DoFTools::extract_boundary_dofs(dof_handler, ComponentMask(), {wall_id}))
          {
            const Point<dim> &X = dof_point[i];
            if (dof_component[i] == 0)
              moment -= (X[1] + U[i + 1]) * unconstrained_residual[i];
            else if (dof_component[i] == 1)
              moment += (X[0] + U[i - 1]) * unconstrained_residual[i];
          }
        moment /= prm.geometry.slice_angle * M_PI / 180.;
        return moment / (scale.R_i * scale.R_i * scale.H) / (0.5 * scale.P_wall);
      }
    const unsigned int component = column ? 0 : twist;
    const IndexSet     wall_dofs = DoFTools::extract_boundary_dofs(
            dof_handler, fe.component_mask(FEValuesExtractors::Scalar(component)), {wall_id});
    double reaction = 0.;
    for (const auto i : wall_dofs)
      reaction += unconstrained_residual[i];
    if (column)
      return reaction / (scale.h * scale.h) / scale.P_wall;
    const double pressure = row ? scale.P_wall : 0.5 * scale.P_wall;
    return reaction / (scale.R_i * scale.R_i * scale.H) / pressure;
  }

  template <int dim>
  Vector<double>
  Problem<dim>::velocity(const double dt) const
  {
    Vector<double> v(U);
    v -= U_n;
    v /= dt;
    if (dim == 2)
      for (types::global_dof_index i = 0; i < v.size(); ++i)
        if (dof_component[i] == twist)
          {
            // v_theta = r dtheta/dt with r = R + u_r of the same node (dofs of a node are
            // consecutive in component order)
            v[i] *= dof_point[i][0] + U[i - twist]; // checked in setup_system()
          }
    return v;
  }

  template <int dim>
  double
  Problem<dim>::steady_window() const
  {
    // the last tenth of the run, but at least its last 0.1 d (the default column's tenth; a
    // tenth of a short run changes too little to tell)
    return std::max(0.1 * scale.u_end, std::min(0.1 * scale.d, scale.u_end));
  }

  namespace
  {
    /// The failure text of a run stopped by a signal after `converged` increments (at least the
    /// loading one: before it, the signal ends the process, core/interrupt.h).
    std::string
    stopped_by_signal(const unsigned int converged, const double run_over_d)
    {
      return std::string("stopped by ") + interrupt::signal_name() + " after increment " +
             std::to_string(converged - 1) + " (of a run to " + format_number(run_over_d) + " d)";
    }
  } // namespace

  template <int dim>
  typename Problem<dim>::RunState
  Problem<dim>::march()
  {
    // Increment 0 loads the body (gravity, wall pressure) with the wall at rest; then the wall
    // moves at v_wall. Increments adapt to the Newton iteration count.
    const double              d  = scale.d;
    double                    du = prm.solver.first_increment * d;
    RunState                  s;
    AffineConstraints<double> step_constraints;
    s.v.reinit(U.size());
    s.rate.reinit(U.size());
    // the progress line's estimate of the time left, at the pace of the last 10 s
    TimeLeft time_left(10., 1.);
    while (s.loading || s.u_wall < scale.u_end * (1. - 1e-12))
      {
        // What is left is divided into equal increments of at most du, so that the run ends
        // on increments of the size it has been taking: smaller ones at the end would move
        // mu_wall by the increment-size dependence of the time integration (0.1 % between
        // 0.005 d and 0.0025 d increments in the column, docs/ngf.md). With du fixed, this
        // gives the same step at every increment to the end.
        const double remaining = scale.u_end - s.u_wall;
        const double step =
            s.loading ? 0. : remaining / std::max(1., std::ceil(remaining / du - 1e-9));
        const double dt = (s.loading ? du : step) / scale.v_wall;
        predict(s.rate, dt);
        make_constraints(step_constraints, s.u_wall + step, false);
        step_constraints.distribute(U);
        const solvers::NewtonStats stats      = newton(dt, s.increment);
        const unsigned int         iterations = stats.iterations;
        if (stats.interrupted || (stats.converged && interrupt::requested()))
          {
            s.interrupted = true;
            if (!stats.converged) // the increment's state is abandoned, as a cut one would be
              {
                U = U_n;
                assemble(0., false);
              }
          }
        if (stats.interrupted)
          {
            s.failure = stopped_by_signal(s.increment, scale.u_end / d);
            break;
          }
        if (!stats.converged)
          {
            du *= 0.25;
            ++s.cuts;
            // the same increment number starts again in the table and in newton.csv
            log.table() << std::setw(6) << s.increment << "  not converged: increment cut to "
                        << (s.loading ? du / scale.v_wall : du / d)
                        << (s.loading ? " s (loading time step)" : " d of wall displacement")
                        << '\n';
            if (du < 1e-6 * prm.solver.first_increment * d)
              {
                U = U_n;
                // the converged state: with dt = 0 the update returns it unchanged
                assemble(0., false);
                s.failure = newton_failure(s.loading, dt, du, s.u_wall);
                break;
              }
            continue;
          }
        // converged: commit the plastic distortion and the fields
        for (unsigned int c = 0; c < points.size(); ++c)
          for (unsigned int q = 0; q < points[c].size(); ++q)
            Fp_n[c][q] = points[c][q].Fp;
        if (!s.loading)
          {
            s.v    = velocity(dt);
            s.rate = increment_rate(dt);
            s.u_wall += step;
            s.last_step = step;
            s.mu_wall   = wall_stress_ratio();
            // The last state at or before the start of the window, for the steadiness verdict.
            if (s.u_wall <= scale.u_end - steady_window() * (1. - 1e-12))
              {
                s.u_wall_window  = s.u_wall;
                s.mu_wall_window = s.mu_wall;
                s.v_window       = steady_velocity(s.v, s.rate);
              }
            s.h_disp.push_back(s.u_wall / d);
            s.h_mu.push_back(s.mu_wall);
            s.h_iter.push_back(iterations);
          }
        U_n = U;
        before_results.reset(); // the loaded body is a state to write
        s.total_iterations += iterations;
        s.max_iterations = std::max(s.max_iterations, iterations);
        const unsigned int done = s.increment++; // as log.txt and newton.csv number it
        s.loading = false;
        if (iterations <= 4)
          du = std::min(du * prm.solver.growth, prm.solver.max_increment * d);
        std::ostringstream p;
        p << "increment " << done << ": wall displacement " << s.u_wall / d << " d of "
          << scale.u_end / d << ", mu_wall " << s.mu_wall << ", " << iterations
          << " Newton iterations";
        // The time left at the pace of the last 10 s, once the increments have reached
        // Solver/Max increment: while they grow (the yielding transient) the pace says little
        // of what is left.
        if (du < prm.solver.max_increment * d * (1. - 1e-12))
          time_left.restart();
        time_left.record(log.elapsed(), s.u_wall);
        if (const auto seconds = time_left.seconds_to(scale.u_end))
          p << ", about " << std::lround(*seconds) << " s left";
        log.progress(p.str());
        if (s.interrupted)
          {
            s.failure = stopped_by_signal(s.increment, scale.u_end / d);
            break;
          }
      }
    return s;
  }

  template <int dim>
  nlohmann::json
  Problem<dim>::describe_run(const RunState &s) const
  {
    const double   d = scale.d;
    nlohmann::json summary;
    summary["case"]     = prm.name;
    summary["model"]    = "ngf";
    summary["geometry"] = prm.geometry.shape;
    summary["mesh"]     = {{"elements", tria.n_active_cells()},
                           {"h_over_d", scale.h / d},
                           {"dofs", dof_handler.n_dofs()}};
    // The annulus's height is divided into elements of its own size, round(H / h) of them
    // (Parameters::scales), which may differ from the radial h.
    if (!column && !row)
      summary["mesh"]["h_vertical_over_d"] = scale.H / scale.n_2 / d;
    if (column)
      {
        summary["P_wall_over_phi_rho_s_G_d"] = prm.loading.wall_pressure;
        summary["v_wall_over_sqrt_G_d"]      = prm.loading.wall_speed;
      }
    else if (row)
      {
        summary["R_i_over_d"]                       = prm.geometry.inner_radius;
        summary["R_i_Omega_sqrt_rho_s_over_P_wall"] = prm.loading.wall_speed;
      }
    else
      {
        summary["R_i_over_d"]              = prm.geometry.inner_radius;
        summary["R_i_Omega_over_sqrt_G_d"] = prm.loading.wall_speed;
      }
    // null until an increment past the loading step has converged (there is no wall reaction
    // of a sheared state before)
    summary["mu_wall"] = s.u_wall > 0. ? nlohmann::json(s.mu_wall) : nlohmann::json(nullptr);
    summary["newton"]  = {
         {"increments", s.increment},
         {"iterations", s.total_iterations},
         {"iterations_per_increment", double(s.total_iterations) / std::max(1U, s.increment)},
         {"max_iterations", s.max_iterations},
         {"increment_cuts", s.cuts},
         {"last_increment_over_d", s.last_step / d}};
    summary["wall_displacement_over_d"] = s.u_wall / d;
    return summary;
  }

  template <int dim>
  std::pair<nlohmann::json, std::string>
  Problem<dim>::judge_steadiness(const RunState &s) const
  {
    // Steadiness over the window (the issue's "run until the velocity field and the wall stress
    // ratio are steady"): the relative change of mu_wall and the largest change of the
    // wall-parallel velocity, over v_wall. While the body is still loading elastically, mu_wall
    // grows in proportion to the wall displacement, so the first test catches runs that are
    // too short to yield.
    constexpr double   steady_mu_tolerance = 1e-3, steady_velocity_tolerance = 1e-2;
    const double       d      = scale.d;
    nlohmann::json     steady = {{"window_over_d", 0.}, {"steady", false}};
    std::ostringstream why_not;
    why_not << std::setprecision(3);
    const bool completed = s.u_wall >= scale.u_end * (1. - 1e-12);
    if (completed && s.u_wall_window >= 0.)
      {
        const Vector<double> v_end = steady_velocity(s.v, s.rate);
        double               dv    = 0.;
        for (types::global_dof_index i = 0; i < v_end.size(); ++i)
          dv = max_abs(dv, (v_end[i] - s.v_window[i]) / scale.v_wall);
        // relative to the larger of the two (a mu_wall of exactly 0, a body not loaded at all,
        // is steady if it stays 0)
        const double scale_mu = std::max(std::abs(s.mu_wall), std::abs(s.mu_wall_window));
        const double dmu = scale_mu == 0. ? 0. : std::abs(s.mu_wall - s.mu_wall_window) / scale_mu;
        steady           = {{"window_over_d", (s.u_wall - s.u_wall_window) / d},
                            {"mu_wall_relative_change", dmu},
                            {"velocity_change_over_v_wall", dv},
                            {"steady", dmu <= steady_mu_tolerance && dv <= steady_velocity_tolerance}};
        why_not << "not steady over the last " << (s.u_wall - s.u_wall_window) / d
                << " d of wall displacement (of " << s.u_wall / d << " d): mu_wall changed by "
                << dmu << " of itself (limit " << steady_mu_tolerance << ") and the velocity by "
                << dv << " v_wall (limit " << steady_velocity_tolerance << ")";
      }
    else if (!completed)
      why_not << "not steady: the run stopped at " << s.u_wall / d
              << " d of wall displacement, before the last " << steady_window() / d
              << " d over which steadiness is judged";
    else if (steady_window() >= scale.u_end * (1. - 1e-12))
      why_not << "not steady: a run of " << scale.u_end / d
              << " d of wall displacement is too short to tell (steadiness compares the "
                 "end with the state 0.1 d of wall displacement before it)";
    else
      why_not << "not steady: the run is barely longer than the " << steady_window() / d
              << " d of wall displacement over which steadiness is judged (its first "
                 "increment reaches into them)";
    return {steady, why_not.str()};
  }

  template <int dim>
  void
  Problem<dim>::warn_about_run(const RunState &s, const bool steady,
                               const std::string &why_not_steady)
  {
    const double d = scale.d;
    if (!s.failure.empty() && !s.interrupted)
      {
        std::ostringstream w;
        // (a failed loading step has no results: run() throws NoResults before this)
        w << std::setprecision(3) << "Newton failed (see the log): ";
        if (s.u_wall == 0.)
          w << "the results are those of the loaded body at rest, before any shear";
        else
          w << "the results are those of the last converged increment, at " << s.u_wall / d
            << " d of wall displacement of " << scale.u_end / d << " d, not of a steady flow";
        report.warn(w.str());
      }
    if ((s.failure.empty() || s.interrupted) && !steady)
      report.warn(why_not_steady +
                  (s.interrupted
                       ? ": rerun it to the end before using mu_wall, W/d or the profiles as "
                         "steady results"
                   : slice ? ": run further (Loading/Wall rotation) before using mu_wall, W/d or "
                             "the profiles as steady results; beyond about 5 degrees the slice "
                             "drifts from the quad section (docs/ngf.md), which is the one for "
                             "long runs"
                           : std::string(": run further (Loading/") +
                                 (column ? "Wall displacement" : "Wall rotation") +
                                 ") before using mu_wall, W/d or the profiles as steady results"));
    // The implicit, first-order time integration (Section 4) gives a steady state that depends
    // on the increment: mu_wall falls below its increment-converged value by about
    // rate x (increment / d), with the rate measured per geometry at the cases' parameters
    // (docs/ngf.md, "Increment size"): 10 % in the shear column (-0.08 % at the default
    // 0.01 d, -2.3 % at 0.2 d), 8 to 5 % in the annulus row (R_i = 20 d to 100 d), 3 % in the
    // annulus with gravity. Steadiness cannot see that bias, so increments whose estimated bias
    // exceeds 0.25 % are named (the column's 0.025 d; 0.031 d in the row, 0.083 d with gravity).
    const double rate_percent = column ? 10. : row ? 8. : 3.;
    if (s.failure.empty() && rate_percent * s.last_step / d > 0.25)
      {
        std::ostringstream w;
        w << std::setprecision(3) << "the run ended on increments of " << s.last_step / d
          << " d of wall displacement: the implicit time integration then lowers the steady "
             "mu_wall by "
          << "about " << rate_percent * s.last_step / d << " %"
          << (row ? " at R_i = 20 d, less at larger radii (8 % x increment / d at 20 d, 5 % at "
                    "100 d; docs/ngf.md)"
                  : " (docs/ngf.md)")
          << "; Solver/Max increment = " << 0.1 / rate_percent << " or less keeps it under 0.1 %";
        report.warn(w.str());
      }
  }

  template <int dim>
  void
  Problem<dim>::warn_if_below_mu_s(const nlohmann::json &summary, const bool steady_flow)
  {
    // Steady flow starts where mu >= mu_s (g_loc = 0 below it, (22)), and mu is largest at the
    // driven wall in every geometry here: below mu_s there, the mesh does not resolve the flow
    // at the wall (g = 0 there on coarse meshes, docs/ngf.md) or the body has not yielded.
    // Fluidity fed in through the boundaries (g_wall > 0 above the fluidity beside it, zeta > 0)
    // lets material flow below mu_s. The test therefore applies unless the boundaries feed
    // fluidity in, in net: a g_wall below the fluidity beside the wall takes fluidity out, like
    // g = 0, and a source elsewhere may not make up for it.
    // The flow rule sees tau / p, not tau / P_wall: where the wall's pressure is not the applied
    // one (the annulus row on large increments: 0.97 P_wall at 0.5 d, mu_wall 0.377 with
    // tau / p = 0.389 > mu_s), the local ratio mu_wall_local (postprocess()) is the one to test.
    if (!summary.contains("mu_wall") || !summary.at("mu_wall").is_number())
      return;
    const bool   local    = summary.contains("mu_wall_local");
    const double mu_wall  = summary.at(local ? "mu_wall_local" : "mu_wall").template get<double>();
    const auto   positive = [](const auto &condition) { return condition.second > 0.; };
    const bool fluidity_source = std::any_of(g_dirichlet.begin(), g_dirichlet.end(), positive) ||
                                 std::any_of(g_neumann.begin(), g_neumann.end(), positive);
    const bool fed_by_boundaries = fluidity_source && boundary_fluidity_supply > 0.;
    if (fed_by_boundaries || mu_wall >= prm.material.nonlocal.mu_s)
      return;
    std::ostringstream w;
    w << (local ? "the stress ratio at the driven wall, tau / p = mu_wall_local = " : "mu_wall = ")
      << mu_wall << ", is below mu_s = " << prm.material.nonlocal.mu_s
      << ": a steady flow needs mu >= mu_s where it starts, so ";
    if (!steady_flow)
      {
        // (the "not steady" warning says how to run further)
        w << "the body has likely not yielded at the wall yet (the run is not steady); if it "
             "stays below mu_s once steady, the mesh does not resolve the flow at the wall ("
          << refine_advice() << ")";
        report.warn(w.str());
        return;
      }
    w << "either the body has not yielded, or the mesh does not resolve the flow at the wall";
    // (with homogeneous Neumann conditions only, the supply is zero to the Newton
    // tolerance, and its sign means nothing)
    const bool conditions = !g_dirichlet.empty() || std::any_of(g_neumann.begin(), g_neumann.end(),
                                                                [](const auto &condition) {
                                                                  return condition.second != 0.;
                                                                });
    if (conditions && boundary_fluidity_supply < 0.)
      w << " (the fluidity conditions take fluidity out of the body in net, "
           "as g = 0 or a g_wall below the fluidity beside the wall does: the boundary "
           "layer this makes needs h well below d, docs/ngf.md; refine Geometry/Element "
           "size)";
    else
      w << " (" << refine_advice() << ")";
    report.warn(w.str());
  }

  template <int dim>
  void
  Problem<dim>::report_distortion(nlohmann::json &summary)
  {
    // The slice's Lagrangian cells turn with the material, each radial line by its own angle.
    // A cell whose inner nodes have turned by dtheta more than its outer ones is stretched
    // around the arc by about r dtheta, while its faces Theta = const turn by dtheta: the
    // trilinear map then changes volume across the cell by about r dtheta^2 / h, growing as
    // the square of the rotation. F-bar hides it from the pressure, not from the deviatoric
    // strain at the Gauss points, and the flow drifts from the quad section's, whose cells
    // stay in the (r, z) plane. Measured at h = d (docs/ngf.md): spread 0.007, 0.016, 0.029,
    // 0.071 after 4, 6, 8, 12 degrees; surface velocity off the quad section's by 0.003,
    // 0.009, 0.019, 0.059 of the wall speed. A wider slice distorts sooner (after 4 degrees:
    // 0.007, 0.013, 0.019 for 0.1, 1, 2 degrees of slice; W/d 2.733, 2.708, 2.680).
    if (dim != 3)
      return;
    const double spread                           = volume_change_spread();
    summary["distortion"]["volume_change_spread"] = spread;
    if (!slice || spread <= 0.01)
      return;
    std::ostringstream w;
    w << std::setprecision(3)
      << "the slice's cells are sheared around the arc by the wall rotation: the "
         "volume change at their Gauss points differs from that at their centroids by "
         "up to "
      << 100. * spread
      << " % (above 1 %, the surface velocity drifts from the quad section's: 0.009 of "
         "the wall speed at 1.6 %, 0.019 at 2.9 %, 0.059 at 7.1 %, docs/ngf.md); ";
    if (prm.geometry.slice_angle > 0.1)
      w << "a slice wider than the paper's 0.1 degree distorts sooner (Geometry/Slice "
           "angle = "
        << prm.geometry.slice_angle << "); ";
    w << "for rotations beyond about 5 degrees use the quad section (Geometry/Shape = "
         "annulus)";
    report.warn(w.str());
  }

  template <int dim>
  Results
  Problem<dim>::run()
  {
    // Until the loading increment has converged (march()), a signal ends the run at once:
    // nothing to write yet.
    before_results.emplace(out.left_as_it_was());
    compute_reference();
    make_mesh();
    setup_system();
    const double d = scale.d;
    log.print("ngf: " + prm.geometry.shape + ", " + std::to_string(tria.n_active_cells()) +
              (dim == 3 ? " bricks" : " generalized-axisymmetric quads") + ", h/d = " +
              format_number(scale.h / d) + ", " + std::to_string(dof_handler.n_dofs()) + " dofs\n");
    warn_if_outside_elastic_range();
    log.table() << "Newton iterations (R_u, R_g: normalised L_inf residuals, Henann 6.1)\n"
                << std::setw(6) << "incr" << std::setw(6) << "iter" << std::setw(12) << "R_u"
                << std::setw(12) << "R_g" << '\n';

    const RunState s = march();
    before_results.reset();
    if (s.increment == 0) // the loading increment failed: no state to write
      throw NoResults(s.failure);
    nlohmann::json summary       = describe_run(s);
    const auto [steady, why_not] = judge_steadiness(s);
    summary["steady_state"]      = steady;
    const bool steady_flow       = steady.at("steady").template get<bool>();
    warn_about_run(s, steady_flow, why_not);
    report_distortion(summary);
    // The band's own warnings only for a run that reached a steady flow: before that, the
    // profile is a loading one ("not steady" says so).
    postprocess(summary, s.v, s.failure.empty() && steady_flow);
    if (s.failure.empty())
      warn_if_below_mu_s(summary, steady_flow);
    if (prm.output.write_vtu)
      write_vtu(s.v);
    write_histories(s.h_disp, s.h_mu, s.h_iter);
    report.timings         = {{"assembly_s", assembly_seconds}, {"linear_solve_s", solve_seconds}};
    summary["converged"]   = s.failure.empty();
    summary["interrupted"] = s.interrupted;
    report.finish(summary,
                  s.failure.empty() ? ""
                                    : s.failure + "; the last converged state (wall displacement " +
                                          format_number(s.u_wall / d) + " d) is written to " +
                                          out.target() + " (see log.txt)",
                  s.interrupted);
    log.print("ngf: mu_wall = " + summary["mu_wall"].dump() +
              ", W/d = " + summary["shear_band_width_over_d"].dump() + ", " +
              std::to_string(s.increment) + " increments, " + std::to_string(s.total_iterations) +
              " Newton iterations, " + std::to_string(log.elapsed()) + " s\n");
    return {summary};
  }

  /// The paper's cases strain the grains elastically by about 1e-4 (p / B, tau / S at
  /// S = 1 MPa); loads of the order of the moduli compact the bed by tens of per cent, where the
  /// quadratic energy (12) and phi = const (27) stop being a model of a granular bed.
  template <int dim>
  double
  Problem<dim>::elastic_strain_scale() const
  {
    const double p_max = column ? scale.P_wall + scale.body_force * scale.depth
                                : std::max(scale.P_wall, scale.body_force * scale.H);
    return p_max / std::min(prm.material.elastic.S, prm.material.elastic.B);
  }

  template <int dim>
  bool
  Problem<dim>::outside_elastic_range() const
  {
    const double strain = elastic_strain_scale();
    return strain > 1e-2 || strain < 1e-9;
  }

  template <int dim>
  void
  Problem<dim>::warn_if_outside_elastic_range()
  {
    if (!outside_elastic_range())
      return;
    const double       strain = elastic_strain_scale();
    std::ostringstream w;
    w << std::setprecision(3) << "the largest pressure, about "
      << strain * std::min(prm.material.elastic.S, prm.material.elastic.B) << " Pa, is " << strain
      << " times the smaller elastic modulus: ";
    // Far below, the elastic strains drown in the round-off of the positions: the column with
    // S = 1e13 Pa (1e-11) failed in its first increment, with 1e12 Pa it ran.
    if (strain > 1e-2)
      w << "elastic strains that large are outside the model's intended range (Henann 6: about "
           "1e-4)";
    else
      w << "elastic strains that small are lost in the round-off of the positions, and Newton "
           "may fail (Henann 6: about 1e-4)";
    report.warn(w.str());
  }

  /// U at the start of an increment of length dt: U_n continued at the last increment's rate
  /// (the steady flow is then almost exact). The slice turns about z, so its x and y rates are
  /// kept as (dr/dt, dphi/dt) of each node: a linear extrapolation of Cartesian displacements
  /// would cut the chord of the arc, an error of R dphi^2 / 2 that exceeds the elastic strains
  /// at the wall.
  template <int dim>
  void
  Problem<dim>::predict(const Vector<double> &rate, const double dt)
  {
    U = U_n;
    for (types::global_dof_index i = 0; i < U.size(); ++i)
      if (slice && dof_component[i] == 0)
        {
          const Point<dim> &X = dof_point[i];
          const double      x = X[0] + U_n[i], y = X[1] + U_n[i + 1];
          const double      r   = std::hypot(x, y) + rate[i] * dt;
          const double      phi = std::atan2(y, x) + rate[i + 1] * dt;
          U[i]                  = r * std::cos(phi) - X[0];
          U[i + 1]              = r * std::sin(phi) - X[1];
        }
      else if (dof_component[i] < 3 && !(slice && dof_component[i] == 1))
        U[i] += rate[i] * dt;
  }

  /// Why the run stops when an increment cannot be completed even at the smallest increment:
  /// the attempt's time step or wall displacement, and its best iterate.
  template <int dim>
  std::string
  Problem<dim>::newton_failure(const bool loading, const double dt, const double du,
                               const double u_wall) const
  {
    std::ostringstream s;
    if (loading)
      {
        s << "Newton did not converge in the loading step (increment 0: gravity and wall "
             "pressure applied with the wall at rest), even over a time step of "
          << dt << " s";
        // At rest the fluidity has no source, and an outward flux needs g < 0, which the
        // model excludes (g >= 0).
        for (const auto &[name, zeta] : prm.fluidity_neumann())
          if (zeta < 0.)
            s << "; the Neumann fluidity condition '" << name << ": " << zeta
              << "' (an outward flux of fluidity) has no solution with g >= 0 while the body is "
                 "at rest";
      }
    else
      s << "Newton did not converge at wall displacement " << u_wall / scale.d
        << " d even with an increment of " << du / scale.d << " d";
    // The last attempt's best iterate (least max(R_u, R_g)): below 1e-6 (the default
    // tolerance) but not below a tighter one, its residuals may be at their round-off floor
    // (about 5e-14 for R_u while the total deformation is small, more once it is of order 1;
    // docs/ngf.md), and a looser tolerance is the remedy.
    const NewtonRecord *best       = nullptr;
    bool                not_finite = false;
    for (auto r = newton_log.rbegin(); r != newton_log.rend(); ++r)
      {
        not_finite = not_finite || !std::isfinite(r->R_u) || !std::isfinite(r->R_g);
        if (!best || std::max(r->R_u, r->R_g) < std::max(best->R_u, best->R_g))
          best = &*r;
        if (r->iteration == 0)
          break;
      }
    if (best)
      {
        s << " (best iterate of the last attempt: iteration " << best->iteration << ", R_u "
          << best->R_u << ", R_g " << best->R_g << ")";
        if (std::max(best->R_u, best->R_g) < 1e-6)
          s << "; below 1e-6 but not below Solver/Tolerance = " << prm.solver.tolerance
            << ", they may have reached their round-off floor (docs/ngf.md): try a larger "
               "tolerance";
      }
    // An attempt that used all its iterations with the residual still falling was stopped by
    // the cap, not by a diverging Newton: at Max Newton iterations = 1 or 2 the shear column's
    // loading step or first increments cannot reach 1e-6 (2: R_g 1.04e-6 at the last iterate),
    // and cutting the increment does not help.
    if (!newton_log.empty() && best && !not_finite)
      {
        const NewtonRecord &last  = newton_log.back();
        const NewtonRecord *first = &last;
        for (auto r = newton_log.rbegin(); r != newton_log.rend() && first->iteration > 0; ++r)
          first = &*r;
        if (last.iteration >= prm.solver.max_iterations &&
            std::max(last.R_u, last.R_g) < std::max(first->R_u, first->R_g))
          s << "; the last attempt was still converging when it reached Solver/Max Newton "
               "iterations = "
            << prm.solver.max_iterations << ": raise it (default "
            << solvers::NewtonOptions{}.max_iterations << ")";
      }
    // A residual that is not a number is an overflow, not a slow convergence: smaller
    // increments do not help, and the usual cause is an input value far out of scale (a
    // fluidity condition of 1e300 passes its check, >= 0 or any finite zeta, and overflows).
    if (not_finite)
      s << "; a residual was not finite (an overflow, which smaller increments do not cure): look "
           "for a value in the case file far out of physical scale (moduli, "
           "loading, fluidity boundary conditions)";
    // An element larger than the cooperativity length (24) does not resolve the fluidity
    // equation (23): with linear elements its matrix (xi^2 stiffness plus consistent mass) loses
    // the sign pattern that keeps g >= 0 once h exceeds sqrt(6) xi (1D), the Newton
    // corrections drive g below 0 beside the band, the projection onto g >= 0 cuts the steps,
    // and Newton fails as the flow starts (shear column, default parameters: h/d = 2.5 runs, 3
    // and 4 fail; at h/d = 1/3 a cap of 0.2 d runs and 0.1 d fails). points holds the last
    // converged state.
    double xi_min = std::numeric_limits<double>::infinity();
    for (const auto &cell_points : points)
      for (const auto &point : cell_points)
        xi_min = std::min(xi_min, point.xi);
    // the annulus's height has elements of its own size (Parameters::scales)
    const double h = column || row ? scale.h : std::max(scale.h, scale.H / scale.n_2);
    // Below sqrt(6) xi the sign pattern holds, but a mesh coarser than xi can still fail: the
    // annulus with gravity (xi about 0.94 d) failed at h = 2 d (R_g stalled at 1.5e-6) and ran
    // at 1.5 d (a review, session 16).
    if (!loading && prm.solver.fluidity != "local" && h > xi_min)
      {
        const bool unresolved = h > std::sqrt(6.) * xi_min;
        s << std::setprecision(3) << "; the element size h = " << h / scale.d << " d is "
          << h / xi_min << " times the smallest cooperativity length xi = " << xi_min / scale.d
          << " d (Henann (24)), ";
        if (unresolved)
          s << "so the mesh does not resolve the fluidity equation (23): its Newton corrections "
               "drive g below 0 beside the band (with linear elements g stays >= 0 only for h "
               "below about sqrt(6) xi = 2.4 xi); ";
        else
          s << "and meshes coarser than xi may not converge (the annulus with gravity fails at "
               "h = 2 d, runs at 1.5 d); ";
        // the cap (footnote ||) bounds xi only where it is what makes xi small
        const bool at_cap = xi_min >= 0.99 * prm.material.nonlocal.xi_cap_over_d * scale.d;
        if (at_cap)
          s << "raise Material/Cooperativity length cap (xi is at the cap, " << xi_min / scale.d
            << " d) or ";
        s << "refine Geometry/Element size";
        if (unresolved)
          s << " below " << std::sqrt(6.) * xi_min / scale.d << " d at least";
        s << (at_cap ? "" : " (the paper uses h/d = 1/3)");
      }
    if (outside_elastic_range())
      s << "; the elastic strains, about " << elastic_strain_scale()
        << " (pressure over modulus), are outside the range the model and its solver are meant "
           "for, about 1e-4 (Material/Shear modulus, Material/Bulk modulus, Loading)";
    return s.str();
  }

  /// (U - U_n) / dt; for the slice, (dr/dt, dphi/dt) of each node in place of its x and y
  /// rates (see predict()).
  template <int dim>
  Vector<double>
  Problem<dim>::increment_rate(const double dt) const
  {
    Vector<double> rate = U;
    rate -= U_n;
    rate /= dt;
    if (slice)
      for (types::global_dof_index i = 0; i < U.size(); ++i)
        if (dof_component[i] == 0)
          {
            // x and y dofs of a node are adjacent
            const Point<dim> &X  = dof_point[i];
            const double      x1 = X[0] + U[i], y1 = X[1] + U[i + 1];
            const double      x0 = X[0] + U_n[i], y0 = X[1] + U_n[i + 1];
            rate[i]     = (std::hypot(x1, y1) - std::hypot(x0, y0)) / dt;
            rate[i + 1] = std::remainder(std::atan2(y1, x1) - std::atan2(y0, x0), 2. * M_PI) / dt;
          }
    return rate;
  }

  template <int dim>
  Vector<double>
  Problem<dim>::steady_velocity(const Vector<double> &v, const Vector<double> &rate) const
  {
    Vector<double> w(v.size());
    for (types::global_dof_index i = 0; i < v.size(); ++i)
      if (slice && dof_component[i] == 0)
        {
          // x and y dofs of a node are adjacent; rate holds (dr/dt, dphi/dt) there
          const Point<dim> &X = dof_point[i];
          w[i]                = rate[i];
          w[i + 1]            = std::hypot(X[0] + U[i], X[1] + U[i + 1]) * rate[i + 1];
        }
      else if (!slice && dof_component[i] == (column ? 0U : twist))
        w[i] = v[i];
    return w;
  }

  template <int dim>
  double
  Problem<dim>::wall_parallel_speed(const types::global_dof_index i, const Vector<double> &v) const
  {
    if (column)
      return v[i];
    if (!slice)
      return v[i + twist];
    // The circumferential part of (v_x, v_y) at the node's current angle: the slice's nodes
    // turn with the material (at the reference angle it would carry a factor cos(rotation)).
    const Point<dim> &X   = dof_point[i];
    const double      phi = std::atan2(X[1] + U[i + 1], X[0] + U[i]);
    return -std::sin(phi) * v[i] + std::cos(phi) * v[i + 1];
  }

  template <int dim>
  double
  Problem<dim>::volume_change_spread() const
  {
    if (dim != 3)
      return 0.;
    const QGauss<dim>                gauss(2), middle(1);
    FEValues<dim>                    at_q(fe, gauss, update_gradients);
    FEValues<dim>                    at_c(fe, middle, update_gradients);
    const FEValuesExtractors::Vector displacement(0);
    std::vector<Tensor<2, dim>>      grad_q(gauss.size()), grad_c(1);
    const auto                       J = [](const Tensor<2, dim> &grad_u) {
      return determinant(Tensor<2, dim>(unit_symmetric_tensor<dim>()) + grad_u);
    };
    double spread = 0.;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        at_q.reinit(cell);
        at_c.reinit(cell);
        at_q[displacement].get_function_gradients(U, grad_q);
        at_c[displacement].get_function_gradients(U, grad_c);
        const double J_c = J(grad_c[0]);
        for (const auto &g : grad_q)
          spread = max_abs(spread, J(g) / J_c - 1.);
      }
    return spread;
  }

  // Each member defined here is instantiated here, for both element types (ngf_problem.h).
#define GRANFLOW_NGF_INSTANTIATE(D)                                                                  \
  template double                                 Problem<D>::wall_stress_ratio() const;             \
  template Vector<double>                         Problem<D>::velocity(const double dt) const;       \
  template double                                 Problem<D>::steady_window() const;                 \
  template Problem<D>::RunState                   Problem<D>::march();                               \
  template nlohmann::json                         Problem<D>::describe_run(const RunState &s) const; \
  template std::pair<nlohmann::json, std::string> Problem<D>::judge_steadiness(const RunState &s)    \
      const;                                                                                         \
  template void           Problem<D>::warn_about_run(const RunState &s, const bool steady,           \
                                                     const std::string &why_not_steady);             \
  template void           Problem<D>::warn_if_below_mu_s(const nlohmann::json &, const bool);        \
  template void           Problem<D>::report_distortion(nlohmann::json &summary);                    \
  template Results        Problem<D>::run();                                                         \
  template double         Problem<D>::elastic_strain_scale() const;                                  \
  template bool           Problem<D>::outside_elastic_range() const;                                 \
  template void           Problem<D>::warn_if_outside_elastic_range();                               \
  template void           Problem<D>::predict(const Vector<double> &rate, const double dt);          \
  template std::string    Problem<D>::newton_failure(const bool loading, const double dt,            \
                                                     const double du, const double u_wall) const;    \
  template Vector<double> Problem<D>::increment_rate(const double dt) const;                         \
  template Vector<double> Problem<D>::steady_velocity(const Vector<double> &v,                       \
                                                      const Vector<double> &rate) const;             \
  template double         Problem<D>::wall_parallel_speed(const types::global_dof_index i,           \
                                                          const Vector<double>         &v) const;            \
  template double         Problem<D>::volume_change_spread() const;

  GRANFLOW_NGF_INSTANTIATE(2)
  GRANFLOW_NGF_INSTANTIATE(3)
#undef GRANFLOW_NGF_INSTANTIATE
} // namespace granflow::ngf::detail

namespace granflow::ngf
{

  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log)
  {
    if (parameters.geometry.shape == "shear column" || parameters.geometry.shape == "annulus slice")
      {
        detail::Problem<3> problem(parameters, output, log);
        return problem.run();
      }
    detail::Problem<2> problem(parameters, output, log);
    return problem.run();
  }
} // namespace granflow::ngf
