// Daviet & Bertails-Descoubes 2016, Sections 4.1-4.5 and 6.1-6.3; see dp_model.h. The run: the
// cone solve (4.4-4.5), the viscosity loop (6.1.3), and what a failed solve reports. The Problem's
// other members are in dp_setup.cc, dp_assemble.cc and dp_postprocess.cc (dp_problem.h).
#include "models/dp/dp_problem.h"

#include <deal.II/grid/grid_tools.h>
#include <filesystem>

namespace granflow::dp::detail
{
  namespace
  {
    /// "1 iteration", "29 iterations" (`what` in the singular).
    std::string
    iterations(const unsigned int n, const std::string &what)
    {
      return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
    }
  } // namespace

  solvers::ConeSolverStats
  Problem::solve_cone_problem()
  {
    solvers::ConeSolverOptions options;
    options.method               = solvers::parse_cone_method(prm.solver.method);
    options.inner_solver         = solvers::parse_inner_solver(prm.solver.inner_solver);
    options.residual             = prm.solver.residual == "alart-curnier"
                                       ? solvers::ResidualKind::alart_curnier
                                       : solvers::ResidualKind::fischer_burmeister;
    options.tolerance            = prm.solver.tolerance;
    options.max_outer_iterations = prm.solver.max_outer_iterations;
    options.max_inner_iterations = prm.solver.max_inner_iterations;
    options.anderson_depth       = prm.solver.anderson_depth;
    options.max_seconds          = prm.solver.max_seconds;
    options.log                  = &log.table();
    options.progress             = [this](const unsigned int k, const double r) {
      // The steps before results end with the solver's first completed iteration: its starting
      // point (no stress, or the interior point's least-squares start) is not worth replacing an
      // earlier run's results with. From then on a signal asks it to stop with its best iterate.
      if (k >= 1)
        before_results.reset();
      std::ostringstream s;
      s << prm.solver.method << " iteration " << k << ": residual " << r << " (target "
        << prm.solver.tolerance << ")";
      log.progress(s.str());
    };
    options.stop_requested = [] { return interrupt::requested(); };
    if (!prm.solver.dump_cone_problem.empty())
      {
        std::string why; // the system's reason, in its own words (strerror), not the library's
        try
          {
            // relative to the output directory, subdirectories included
            const std::filesystem::path dump = out.file(prm.solver.dump_cone_problem);
            std::filesystem::create_directories(dump.parent_path());
            write_file_atomically(dump.string(), [&](std::ostream &file) {
              solvers::write_cone_problem(data, file);
            });
          }
        catch (const std::filesystem::filesystem_error &e)
          {
            why = "cannot create the directory '" + e.path1().string() + "': " + e.code().message();
          }
        catch (const std::exception &e)
          {
            why = e.what();
          }
        if (!why.empty())
          throw InputError(prm.case_file, "Solver/Dump cone problem",
                           "= " + prm.solver.dump_cone_problem + ": cannot be written (" + why +
                               "; expected a file name, relative to the output directory, or a "
                               "writable path)");
      }
    solvers::ConeSolverStats stats;
    try
      {
        // Either method factorises A (Cholesky) first and refuses an A that is not positive
        // definite (solve_cone_problem).
        stats = solvers::solve_cone_problem(data, options, solution);
      }
    catch (const solvers::NotPositiveDefinite &)
      {
        throw InputError(prm.case_file, "Boundary conditions",
                         "its velocity conditions (" + velocity_condition_entries(prm.boundaries) +
                             ") leave a rigid motion of the velocity free (A is singular): "
                             "expected velocity conditions that fix both translations and the "
                             "rotation");
      }
    log.flush_table();

    for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
      u[i] = free_index[i] >= 0 ? free_coefficient[i] * solution.u[free_index[i]] : dirichlet.at(i);
    return stats;
  }

  Problem::ViscosityChange
  Problem::viscosity_change(const std::vector<double> &eta_used) const
  {
    FEValues<dim> fv(mapping, fe_u, quadrature, update_gradients | update_JxW_values);
    const FEValuesExtractors::Vector     velocity(0);
    std::vector<SymmetricTensor<2, dim>> D(quadrature.size());
    double                               change = 0., size = 0., floored = 0., area = 0.;
    std::vector<double>                  eta_of_u;
    std::size_t                          k = 0;
    for (const auto &cell : dof_u.active_cell_iterators())
      {
        fv.reinit(cell);
        fv[velocity].get_function_symmetric_gradients(u, D);
        for (unsigned int q = 0; q < quadrature.size(); ++q, ++k)
          {
            const double eta = eta_of_u.emplace_back(bagnold_viscosity(D[q]));
            change += (eta - eta_used[k]) * (eta - eta_used[k]) * fv.JxW(q);
            size += eta * eta * fv.JxW(q);
            if (eta <= prm.rheology.viscosity_floor)
              floored += fv.JxW(q);
            area += fv.JxW(q);
          }
      }
    return {std::sqrt(change / size), floored / area, // eta >= the viscosity floor > 0
            std::move(eta_of_u)};
  }

  Results
  Problem::run()
  {
    Results results;
    // Until the solver has an iterate to write, a signal ends the run at once (Gmsh's meshing
    // does not poll for it). The scope ends when the solver completes its first iteration
    // (options.progress), or returns before one (converged at once).
    before_results.emplace(out.left_as_it_was());
    if (const auto &dump = prm.solver.dump_cone_problem; !dump.empty() && out.in_target(dump))
      throw InputError(prm.case_file, "Solver/Dump cone problem",
                       "= " + dump + " is in " + out.target() +
                           " itself, which the run fills only when it ends: expected a name "
                           "relative to the output directory (cone.bin) or a path outside it");
    make_mesh();
    setup();
    assemble_constraint_operator();
    if (prm.rheology.Bi > 0. && prm.solver.residual != "alart-curnier")
      log.print("dp: note: Bi > 0, so the residual is Alart-Curnier's (f_AC, Definition 2), not "
                "the " +
                prm.solver.residual + " of Solver/Residual, which covers Bi = 0 only\n");

    const std::size_t   n_qp = mesh.triangulation.n_active_cells() * quadrature.size();
    std::vector<double> eta(n_qp, 1.);
    const bool          bagnold = prm.rheology.viscosity == "bagnold";
    const bool          interior_point =
        solvers::parse_cone_method(prm.solver.method) == solvers::ConeMethod::interior_point;
    unsigned int viscosity_iterations = 0;
    // the Bagnold loop's residual (null in summary.json without a Bagnold viscosity)
    double                   change = std::numeric_limits<double>::quiet_NaN();
    double                   floored_fraction = 0.; // of the area, where |D(u)| < the floor
    solvers::ConeSolverStats stats;
    unsigned int             outer_total = 0, inner_total = 0, fixed_point_steps = 0;
    double                   solve_time = 0., factorize_time = 0.;
    for (;;)
      {
        assemble_velocity_operator(eta);
        set_residual_scale(eta);
        log.phase(interior_point ? "interior-point iterations (" + std::to_string(n_free) +
                                       " free velocity dofs; each factorises its Newton matrix)"
                                 : "factorising A (" + std::to_string(n_free) +
                                       " free velocity dofs), then fixed-point iterations");
        stats = solve_cone_problem();
        before_results.reset();
        outer_total += stats.outer_iterations;
        inner_total += stats.inner_iterations;
        fixed_point_steps += stats.fixed_point_steps;
        solve_time += stats.time_solve;
        factorize_time += stats.time_factorize;
        ++viscosity_iterations;
        std::ostringstream s;
        s << "  solve " << viscosity_iterations << ": ";
        if (!interior_point)
          s << iterations(stats.outer_iterations, "fixed-point iteration");
        else if (stats.fixed_point_steps == 0)
          s << iterations(stats.outer_iterations, "interior-point iteration");
        else // its forms stalled, and its fixed-point stage followed (docs/solvers.md)
          s << iterations(stats.outer_iterations - stats.fixed_point_steps,
                          "interior-point iteration")
            << ", then " << iterations(stats.fixed_point_steps, "fixed-point step") << " ("
            << iterations(stats.inner_iterations, "interior-point iteration") << " in them)";
        s << ", residual " << stats.residual << ", " << stats.time_solve << " s";
        if (!stats.converged || !bagnold)
          {
            log.print(s.str() + (stats.converged     ? "\n"
                                 : stats.interrupted ? " (interrupted)\n"
                                                     : " (not converged)\n"));
            break;
          }
        const ViscosityChange c = viscosity_change(eta);
        change                  = c.relative;
        floored_fraction        = c.floored_area_fraction;
        s << ", viscosity fixed point: relative change of eta = |D(u)| " << change
          << " (the floor binds on " << 100. * floored_fraction << " % of the area)";
        log.print(s.str() + "\n");
        log.progress("viscosity iteration " + std::to_string(viscosity_iterations));
        if (change <= prm.solver.viscosity_tolerance ||
            viscosity_iterations == prm.solver.viscosity_iterations)
          break;
        // Geometric relaxation eta <- sqrt(eta |D(u)|): in a flowing layer the stress does not
        // depend on eta and u scales like 1/eta, so the plain update eta <- |D(u)| cycles
        // between two states; the geometric mean is its fixed point.
        for (std::size_t k = 0; k < eta.size(); ++k)
          eta[k] = std::sqrt(eta[k] * c.eta_of_u[k]);
      }

    // The Bagnold viscosity loop ends on its tolerance or its iteration limit; the run has
    // converged only if both it and the last cone problem have.
    const bool viscosity_converged =
        !bagnold || change <= prm.solver.viscosity_tolerance; // NaN: false

    solver_json = {{"method", prm.solver.method},
                   {"residual_kind",
                    prm.rheology.Bi > 0. ? std::string("alart-curnier") : prm.solver.residual},
                   {"tolerance", prm.solver.tolerance},
                   {"converged", stats.converged && viscosity_converged},
                   {"cone_problem_converged", stats.converged},
                   {"viscosity_converged", viscosity_converged},
                   {"interrupted", stats.interrupted},
                   {"stalled", stats.stalled},
                   {"timed_out", stats.timed_out},
                   {"residual", stats.residual},
                   {"viscosity_iterations", viscosity_iterations},
                   {"viscosity_relative_change", change},
                   {"time_factorize_s", factorize_time},
                   {"time_solve_s", solve_time}};
    if (stats.stalled)
      solver_json["stall_reason"] = stats.stall_reason;
    if (interior_point)
      {
        // All of them: the forms', and those inside the fixed-point stage's steps.
        solver_json["interior_point_iterations"] = outer_total - fixed_point_steps + inner_total;
        solver_json["fixed_point_steps"]         = fixed_point_steps;
      }
    else
      {
        solver_json["inner_solver"]           = prm.solver.inner_solver;
        solver_json["fixed_point_iterations"] = outer_total;
        solver_json["inner_iterations"]       = inner_total;
      }
    if (stats.converged && !viscosity_converged)
      {
        std::ostringstream w;
        w << std::setprecision(3) << "the viscosity fixed point did not converge in "
          << viscosity_iterations << " iterations (last relative change of eta = |D(u)| " << change
          << ", tolerance " << prm.solver.viscosity_tolerance
          << "): every result here is that of its last iterate, not of a solution";
        report.warn(w.str());
      }
    // Where |D(u)| is below the floor, eta is the floor's, not Bagnold's |D(u)|: a few
    // per cent of the layer at most near its free surface (the shipped case: none of its points),
    // but a floor as large as the strain rates makes the whole flow the floor's.
    if (bagnold && floored_fraction > 0.1)
      {
        std::ostringstream w;
        w << std::setprecision(3)
          << "|D(u)| is below Rheology/Viscosity floor = " << prm.rheology.viscosity_floor << " on "
          << 100. * floored_fraction
          << " % of the domain, where the viscosity is the floor's, not Bagnold's eta = |D(u)|. "
             "Where the material is rigid this does not matter; where it flows, its flow is the "
             "floor's, not the Bagnold law's (lower the floor if that flow matters)";
        report.warn(w.str());
      }
    if (!stats.converged)
      {
        // The summary's numbers look like any other run's: say here that they are not a
        // solution's (the exit status and the console say it too).
        std::ostringstream w;
        w << std::setprecision(3) << "the solver "
          << (stats.interrupted ? "was stopped before it reached"
                                : (stats.timed_out ? "ran out of Solver/Max seconds before "
                                                     "reaching"
                                                   : "did not reach"))
          << " its tolerance (residual " << stats.residual << ", tolerance " << prm.solver.tolerance
          << (stats.stalled ? "; it stalled: " : "") << stats.stall_reason
          << "): every result here is that of its best iterate, not of a solution";
        report.warn(w.str());
      }
    postprocess(results);
    if (prm.output.write_vtu)
      write_vtu();
    std::string failure;
    if (!stats.converged)
      failure = solver_failure(stats, interior_point);
    else if (!viscosity_converged)
      failure = "the viscosity fixed point did not converge in " +
                std::to_string(viscosity_iterations) +
                " iterations (raise Solver/Viscosity iterations); the last iterate was written "
                "to " +
                out.target();
    report.finish(results.summary, failure, stats.interrupted); // with postprocess()'s warnings
    return results;
  }

  /// What the exit message says of a cone solve that did not reach its tolerance: how it ended,
  /// what may help, and where its best iterate is.
  std::string
  Problem::solver_failure(const solvers::ConeSolverStats &stats, const bool interior_point) const
  {
    std::ostringstream s;
    const std::string  count = iterations(stats.outer_iterations, "iteration");
    s << "the " << (interior_point ? "interior-point method" : "Cadoux fixed point");
    if (stats.interrupted)
      s << " was stopped by " << interrupt::signal_name() << " at residual " << stats.residual
        << " (tolerance " << prm.solver.tolerance << ") after " << count << ". ";
    else if (stats.stalled)
      s << " stalled at residual " << stats.residual << " (tolerance " << prm.solver.tolerance
        << ") after " << count << ": " << stats.stall_reason
        << " (docs/solvers.md), which higher limits do not change; a looser "
           "Solver/Tolerance, another mesh, "
        << (p1d ? "Solver/Stress element = P1 (slower per iteration; docs/dp.md#solver-limits) "
                : "")
        << (interior_point ? "or Solver/Method = fixed point may. "
            : prm.rheology.mu > 0. || prm.rheology.Bi > 0.
                ? "or Solver/Method = interior point may. "
                : "or another Solver/Inner solver may. ");
    else if (stats.timed_out)
      s << " was stopped by Solver/Max seconds = " << prm.solver.max_seconds << " at residual "
        << stats.residual << " (tolerance " << prm.solver.tolerance << ") after " << count << ". ";
    else
      {
        // A fixed point that stagnates has ended as stalled (FixedPointTunables), above.
        s << " did not reach the tolerance " << prm.solver.tolerance << " (residual "
          << stats.residual << " after " << count << "; raise "
          << (interior_point ? "Solver/Max outer iterations). "
                             : "Solver/Max outer iterations or Max inner iterations). ");
      }
    // The problem is dimensionless (23): a mesh drawn in mm is a silo of 1000 L.
    if (const double size = GridTools::diameter(mesh.triangulation);
        !stats.interrupted && (size > 1e3 || size < 1e-3))
      s << "The mesh is " << size
        << " across: lengths are in units of L (23), and a mesh drawn in other units, mm "
           "say, makes a problem the solvers cannot scale. ";
    s << "The iterate of least residual was written to " << out.target();
    return s.str();
  }
} // namespace granflow::dp::detail

namespace granflow::dp
{
  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log)
  {
    detail::Problem problem(parameters, output, log);
    return problem.run();
  }
} // namespace granflow::dp
