#include "models/ngf/ngf_model.h"

#include "core/errors.h"
#include "models/ngf/ngf_element.h"
#include "postprocess/nonlocal_1d.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace granflow::ngf
{
  namespace
  {
    using namespace dealii;
    constexpr int dim = 3;

    // Boundary ids of the shear column (GridGenerator colorize): z = 0 is the driven wall.
    const std::map<std::string, types::boundary_id> column_boundaries = {{"wall", 4}, {"bottom", 5}};

    struct NewtonRecord
    {
      unsigned int increment, iteration;
      double       R_u, R_g;
    };

    class Problem
    {
    public:
      Problem(const Parameters &prm, OutputDirectory &out, Logger &log);
      Results
      run();

    private:
      void
      make_mesh();
      void
      setup_system();
      /// Periodicity, the wall and bottom displacements at wall displacement `u_wall`, and the fluidity
      /// Dirichlet values; `homogeneous` gives the constraints of the Newton corrections.
      void
      make_constraints(AffineConstraints<double> &c, double u_wall, bool homogeneous) const;
      /// Assembles r (constrained rows zeroed) and, if asked, J; returns the normalised (R_u, R_g).
      std::pair<double, double>
      assemble(double dt, bool with_jacobian);
      bool
      newton(double dt, unsigned int increment, unsigned int &iterations);
      double
      wall_stress_ratio() const;
      void
      postprocess(nlohmann::json &summary, const Vector<double> &velocity);
      void
      write_vtu(const Vector<double> &velocity);

      const Parameters  &prm;
      const Scales       scale;
      OutputDirectory   &out;
      Logger            &log;
      NonlocalElement    element;

      Triangulation<dim>        tria;
      FESystem<dim>             fe;
      DoFHandler<dim>           dof_handler;
      AffineConstraints<double> newton_constraints;
      SparsityPattern           sparsity;
      SparseMatrix<double>      jacobian;
      Vector<double>            U, U_n, residual, unconstrained_residual;
      std::vector<ElementShape> shapes;                    // per cell
      std::vector<std::vector<rheology::Tensor2>> Fp_n;    // per cell, per quadrature point
      std::vector<std::vector<rheology::NonlocalPointUpdate>> points; // last evaluated state
      std::vector<std::pair<types::boundary_id, double>> g_dirichlet, g_neumann;
      std::vector<NewtonRecord> newton_log;
      std::vector<unsigned int> dof_component; // 0-2: u_x, u_y, u_z; 3: g
    };

    Problem::Problem(const Parameters &prm, OutputDirectory &out, Logger &log)
      : prm(prm)
      , scale(prm.scales())
      , out(out)
      , log(log)
      , element(Kinematics::brick, prm.material.elastic, prm.material.nonlocal)
      , fe(FE_Q<dim>(1), dim, FE_Q<dim>(1), 1)
      , dof_handler(tria)
    {
      // names were checked against the geometry by Parameters::validate()
      auto resolve = [&](const std::vector<std::pair<std::string, double>> &list) {
        std::vector<std::pair<types::boundary_id, double>> r;
        for (const auto &[name, value] : list)
          r.emplace_back(column_boundaries.at(name), value);
        return r;
      };
      g_dirichlet = resolve(prm.fluidity_dirichlet());
      g_neumann   = resolve(prm.fluidity_neumann());
    }

    void
    Problem::make_mesh()
    {
      const unsigned int n = static_cast<unsigned int>(std::lround(scale.depth / scale.h));
      GridGenerator::subdivided_hyper_rectangle(tria, {1U, 1U, n}, Point<dim>(0., 0., 0.),
                                                Point<dim>(scale.h, scale.h, scale.depth), true);
    }

    void
    Problem::setup_system()
    {
      dof_handler.distribute_dofs(fe);
      make_constraints(newton_constraints, 0., true);
      DynamicSparsityPattern dsp(dof_handler.n_dofs());
      DoFTools::make_sparsity_pattern(dof_handler, dsp, newton_constraints, false);
      sparsity.copy_from(dsp);
      jacobian.reinit(sparsity);
      U.reinit(dof_handler.n_dofs());
      U_n.reinit(dof_handler.n_dofs());
      residual.reinit(dof_handler.n_dofs());
      unconstrained_residual.reinit(dof_handler.n_dofs());
      dof_component.resize(dof_handler.n_dofs());
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
            dof_component[dofs[i]] = fe.system_to_component_index(i).first;
        }

      // Reference-configuration shape data, once: Q1 with the 2x2x2 Gauss rule (full integration,
      // F-bar against locking) and the centroid gradients of F-bar.
      QGauss<dim>   quadrature(2);
      FEValues<dim> values(fe, quadrature, update_values | update_gradients | update_JxW_values);
      FEValues<dim> centroid(fe, Quadrature<dim>(Point<dim>(0.5, 0.5, 0.5)), update_values | update_gradients);
      const FiniteElement<dim> &scalar = fe.base_element(1);
      shapes.resize(tria.n_active_cells());
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          values.reinit(cell);
          centroid.reinit(cell);
          ElementShape &s = shapes[cell->active_cell_index()];
          s.N.assign(quadrature.size(), std::vector<double>(scalar.n_dofs_per_cell()));
          s.dN_dX.assign(quadrature.size(), std::vector<Tensor<1, dim>>(scalar.n_dofs_per_cell()));
          s.dN_dX_centroid.resize(scalar.n_dofs_per_cell());
          s.N_centroid.resize(scalar.n_dofs_per_cell());
          s.JxW.resize(quadrature.size());
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            {
              const auto [component, node] = fe.system_to_component_index(i);
              if (component != dim) // the fluidity component has the same shape functions
                continue;
              for (unsigned int q = 0; q < quadrature.size(); ++q)
                {
                  s.N[q][node]     = values.shape_value_component(i, q, dim);
                  s.dN_dX[q][node] = values.shape_grad_component(i, q, dim);
                  s.JxW[q]         = values.JxW(q);
                }
              s.dN_dX_centroid[node] = centroid.shape_grad_component(i, 0, dim);
              s.N_centroid[node]     = centroid.shape_value_component(i, 0, dim);
            }
        }
      Fp_n.assign(tria.n_active_cells(),
                  std::vector<rheology::Tensor2>(quadrature.size(), unit_symmetric_tensor<dim>()));
      points.assign(tria.n_active_cells(), std::vector<rheology::NonlocalPointUpdate>(quadrature.size()));
    }

    void
    Problem::make_constraints(AffineConstraints<double> &c, const double u_wall, const bool homogeneous) const
    {
      c.clear();
      std::vector<GridTools::PeriodicFacePair<typename DoFHandler<dim>::cell_iterator>> periodic;
      GridTools::collect_periodic_faces(dof_handler, 0, 1, 0, periodic);
      GridTools::collect_periodic_faces(dof_handler, 2, 3, 1, periodic);
      DoFTools::make_periodicity_constraints<dim, dim>(periodic, c);

      const FEValuesExtractors::Vector u(0);
      const FEValuesExtractors::Scalar ux(0), uy(1), g(dim);
      const double                     s = homogeneous ? 0. : 1.;
      // Henann 6.1: fixed bottom; the wall moves along x and is free along z (loaded by P_wall).
      VectorTools::interpolate_boundary_values(dof_handler, 5, Functions::ZeroFunction<dim>(dim + 1), c,
                                               fe.component_mask(u));
      VectorTools::interpolate_boundary_values(dof_handler, 4,
                                               Functions::ConstantFunction<dim>(s * u_wall, dim + 1), c,
                                               fe.component_mask(ux));
      VectorTools::interpolate_boundary_values(dof_handler, 4, Functions::ZeroFunction<dim>(dim + 1), c,
                                               fe.component_mask(uy));
      for (const auto &[id, value] : g_dirichlet)
        VectorTools::interpolate_boundary_values(dof_handler, id,
                                                 Functions::ConstantFunction<dim>(s * value, dim + 1), c,
                                                 fe.component_mask(g));
      c.close();
    }

    std::pair<double, double>
    Problem::assemble(const double dt, const bool with_jacobian)
    {
      if (with_jacobian)
        jacobian = 0.;
      residual               = 0.;
      unconstrained_residual = 0.;
      const unsigned int n_nodes = fe.base_element(1).n_dofs_per_cell();
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      std::vector<unsigned int>            kernel_index(fe.n_dofs_per_cell());
      for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
        {
          const auto [component, node] = fe.system_to_component_index(i);
          kernel_index[i]              = 4 * node + component;
        }

      ElementInput in;
      in.u.resize(n_nodes);
      in.g.resize(n_nodes);
      in.dt         = dt;
      in.body_force = Tensor<1, dim>({0., 0., scale.body_force}); // (27): gravity along +z, into the bed
      ElementOutput          eo;
      Vector<double>         r_local(fe.n_dofs_per_cell());
      FullMatrix<double>     J_local(fe.n_dofs_per_cell(), fe.n_dofs_per_cell());
      double                 force_scale = 0., fluidity_scale = 0.;
      unsigned int           n_contributions = 0;

      QGauss<dim - 1>   face_quadrature(2);
      FEFaceValues<dim> face(fe, face_quadrature, update_values | update_JxW_values);

      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
            {
              const unsigned int k = kernel_index[i];
              if (k % 4 == 3)
                in.g[k / 4] = U[dofs[i]];
              else
                in.u[k / 4][k % 4] = U[dofs[i]];
            }
          const unsigned int c = cell->active_cell_index();
          in.Fp_n              = Fp_n[c];
          element.evaluate(shapes[c], in, with_jacobian, eo);
          points[c] = eo.points;

          for (unsigned int a = 0; a < n_nodes; ++a)
            {
              force_scale += std::sqrt(eo.residual[4 * a] * eo.residual[4 * a] +
                                       eo.residual[4 * a + 1] * eo.residual[4 * a + 1] +
                                       eo.residual[4 * a + 2] * eo.residual[4 * a + 2]);
              fluidity_scale += std::abs(eo.residual[4 * a + 3]);
              ++n_contributions;
            }

          for (unsigned int i = 0; i < dofs.size(); ++i)
            {
              r_local[i] = eo.residual[kernel_index[i]];
              if (with_jacobian)
                for (unsigned int j = 0; j < dofs.size(); ++j)
                  J_local(i, j) = eo.jacobian(kernel_index[i], kernel_index[j]);
            }

          // (35): external traction and fluidity flux, per unit reference area (the column's wall
          // area does not change). The wall pressure P_wall acts along +z on the face z = 0.
          for (const unsigned int f : cell->face_indices())
            {
              if (!cell->face(f)->at_boundary())
                continue;
              const types::boundary_id id = cell->face(f)->boundary_id();
              double                   zeta = 0.;
              for (const auto &[bid, value] : g_neumann)
                if (bid == id)
                  zeta = value;
              const bool wall = id == column_boundaries.at("wall");
              if (!wall && zeta == 0.)
                continue;
              face.reinit(cell, f);
              for (unsigned int q = 0; q < face_quadrature.size(); ++q)
                for (unsigned int i = 0; i < dofs.size(); ++i)
                  {
                    const unsigned int component = fe.system_to_component_index(i).first;
                    const double       N         = face.shape_value(i, q);
                    if (wall && component == 2)
                      r_local[i] -= N * scale.P_wall * face.JxW(q);
                    if (component == dim)
                      r_local[i] -= N * zeta * face.JxW(q);
                  }
            }

          for (unsigned int i = 0; i < dofs.size(); ++i)
            unconstrained_residual[dofs[i]] += r_local[i];
          if (with_jacobian)
            newton_constraints.distribute_local_to_global(J_local, r_local, dofs, jacobian, residual);
          else
            newton_constraints.distribute_local_to_global(r_local, dofs, residual);
        }

      // Henann 6.1: L_inf norms of the assembled residuals, each normalised by the mean element-level
      // nodal contribution to it.
      double r_u = 0., r_g = 0.;
      for (types::global_dof_index i = 0; i < residual.size(); ++i)
        if (!newton_constraints.is_constrained(i))
          {
            double &r = dof_component[i] == dim ? r_g : r_u;
            r         = std::max(r, std::abs(residual[i]));
          }
      force_scale /= n_contributions;
      fluidity_scale /= n_contributions;
      return {force_scale > 0. ? r_u / force_scale : r_u, fluidity_scale > 0. ? r_g / fluidity_scale : r_g};
    }

    bool
    Problem::newton(const double dt, const unsigned int increment, unsigned int &iterations)
    {
      SparseDirectUMFPACK solver;
      Vector<double>      dU(U.size());
      for (iterations = 0;; ++iterations)
        {
          const auto [R_u, R_g] = assemble(dt, true);
          newton_log.push_back({increment, iterations, R_u, R_g});
          log.table() << std::setw(6) << increment << std::setw(6) << iterations << std::scientific
                      << std::setprecision(3) << std::setw(12) << R_u << std::setw(12) << R_g << std::defaultfloat
                      << '\n';
          if (!std::isfinite(R_u) || !std::isfinite(R_g))
            return false;
          if (R_u <= prm.solver.tolerance && R_g <= prm.solver.tolerance)
            return true;
          if (iterations == prm.solver.max_iterations)
            return false;
          try
            {
              solver.initialize(jacobian);
              dU = residual;
              solver.solve(dU);
            }
          catch (const dealii::SparseDirectUMFPACK::ExcUMFPACKError &)
            {
              return false; // a singular Jacobian: the increment is cut
            }
          dU *= -1.;
          newton_constraints.distribute(dU);
          U += dU;
        }
    }

    double
    Problem::wall_stress_ratio() const
    {
      // mu_wall from the reactions where the wall velocity is prescribed (Henann 6.1): the x-force the
      // wall exerts on the bed per unit area, over P_wall.
      const FEValuesExtractors::Scalar ux(0);
      const IndexSet wall_dofs = DoFTools::extract_boundary_dofs(dof_handler, fe.component_mask(ux), {4});
      double         force     = 0.;
      for (const auto i : wall_dofs)
        force += unconstrained_residual[i];
      return force / (scale.h * scale.h) / scale.P_wall;
    }

    Results
    Problem::run()
    {
      make_mesh();
      setup_system();
      const double d = scale.d;
      log.print("ngf: shear column, " + std::to_string(tria.n_active_cells()) + " bricks, h/d = " +
                std::to_string(scale.h / d) + ", " + std::to_string(dof_handler.n_dofs()) + " dofs\n");
      log.table() << "Newton iterations (R_u, R_g: normalised L_inf residuals, Henann 6.1)\n"
                  << std::setw(6) << "incr" << std::setw(6) << "iter" << std::setw(12) << "R_u" << std::setw(12)
                  << "R_g" << '\n';

      // Increment 0 loads the bed by gravity and P_wall with the wall at rest; then the wall moves at
      // v_wall. Increments adapt to the Newton iteration count.
      const double            u_end = prm.loading.wall_displacement * d;
      double                  du    = prm.solver.first_increment * d;
      double                  u_wall = 0., mu_wall = 0., mu_wall_previous = 0.;
      unsigned int            increment = 0, total_iterations = 0, cuts = 0, max_iterations = 0;
      Vector<double>          velocity(U.size()), velocity_previous(U.size());
      AffineConstraints<double> step_constraints;
      bool                    loading = true;
      std::string             failure; // set when an increment cannot be completed
      std::vector<double>     h_disp, h_mu, h_iter, h_v1; // per increment: the history.csv columns
      while (loading || u_wall < u_end * (1. - 1e-12))
        {
          const double step   = loading ? 0. : std::min(du, u_end - u_wall);
          const double dt     = (loading ? du : step) / scale.v_wall;
          // Predictor: continue the last increment's velocity (the steady flow is then almost exact).
          U = U_n;
          if (!loading)
            for (unsigned int i = 0; i < U.size(); ++i)
              if (dof_component[i] < dim)
                U[i] += velocity[i] * dt;
          make_constraints(step_constraints, u_wall + step, false);
          step_constraints.distribute(U);
          unsigned int iterations = 0;
          if (!newton(dt, increment, iterations))
            {
              du *= 0.25;
              ++cuts;
              if (du < 1e-6 * prm.solver.first_increment * d)
                {
                  std::ostringstream s;
                  s << "Newton did not converge at wall displacement " << u_wall / d << " d even with an increment of "
                    << du / d << " d";
                  failure = s.str();
                  U       = U_n;
                  assemble(0., false); // the converged state: with dt = 0 the update returns it unchanged
                  break;
                }
              continue;
            }
          // converged: commit the plastic distortion and the fields
          for (unsigned int c = 0; c < points.size(); ++c)
            for (unsigned int q = 0; q < points[c].size(); ++q)
              Fp_n[c][q] = points[c][q].Fp;
          if (!loading)
            {
              velocity_previous = velocity;
              velocity          = U;
              velocity -= U_n;
              velocity /= dt;
              u_wall += step;
              mu_wall_previous = mu_wall;
              mu_wall          = wall_stress_ratio();
            }
          if (!loading)
            {
              h_disp.push_back(u_wall / d);
              h_mu.push_back(mu_wall);
              h_iter.push_back(iterations);
              double v_max = 0.;
              for (unsigned int i = 0; i < velocity.size(); ++i)
                if (dof_component[i] == 0)
                  v_max = std::max(v_max, std::abs(velocity[i]));
              h_v1.push_back(v_max / scale.v_wall);
            }
          U_n = U;
          total_iterations += iterations;
          max_iterations = std::max(max_iterations, iterations);
          ++increment;
          loading = false;
          if (iterations <= 4)
            du = std::min(du * prm.solver.growth, prm.solver.max_increment * d);
          std::ostringstream p;
          p << "increment " << increment << ": wall displacement " << u_wall / d << " d, mu_wall " << mu_wall
            << ", " << iterations << " Newton iterations";
          log.progress(p.str());
        }

      nlohmann::json summary;
      summary["case"]  = prm.name;
      summary["model"] = "ngf";
      summary["mesh"]  = {{"elements", tria.n_active_cells()}, {"h_over_d", scale.h / d}, {"dofs", dof_handler.n_dofs()}};
      summary["P_wall_over_phi_rho_s_G_d"] = prm.loading.wall_pressure;
      summary["v_wall_over_sqrt_G_d"]      = prm.loading.wall_speed;
      summary["mu_wall"]                   = mu_wall;
      summary["newton"] = {{"increments", increment},
                           {"iterations", total_iterations},
                           {"iterations_per_increment", double(total_iterations) / std::max(1U, increment)},
                           {"max_iterations", max_iterations},
                           {"increment_cuts", cuts}};
      // Steadiness over the last increment: change of mu_wall and of v / v_wall.
      double dv = 0.;
      for (unsigned int i = 0; i < velocity.size(); ++i)
        if (dof_component[i] == 0)
          dv = std::max(dv, std::abs(velocity[i] - velocity_previous[i]) / scale.v_wall);
      summary["steady_state"] = {{"mu_wall_change_last_increment", std::abs(mu_wall - mu_wall_previous)},
                                 {"velocity_change_last_increment", dv}};
      postprocess(summary, velocity);
      if (prm.output.write_vtu)
        write_vtu(velocity);
      std::vector<double> inc, it, ru, rg;
      for (const auto &r : newton_log)
        {
          inc.push_back(r.increment);
          it.push_back(r.iteration);
          ru.push_back(r.R_u);
          rg.push_back(r.R_g);
        }
      out.write_csv("history.csv", {"wall_displacement_over_d", "mu_wall", "newton_iterations", "max_v_over_v_wall"},
                    {h_disp, h_mu, h_iter, h_v1});
      out.write_csv("newton.csv", {"increment", "iteration", "R_u", "R_g"}, {inc, it, ru, rg});
      summary["timings"]   = {{"total_s", log.elapsed()}};
      summary["converged"] = failure.empty();
      summary["wall_displacement_over_d"] = u_wall / d;
      out.write_json("summary.json", summary);
      if (!failure.empty())
        throw ConvergenceError(failure + "; the last converged state (wall displacement " + std::to_string(u_wall / d) +
                               " d) is written to " + out.target() + " (see log.txt)");
      log.print("ngf: mu_wall = " + std::to_string(mu_wall) + ", W/d = " +
                std::to_string(summary.value("shear_band_width_over_d", 0.)) + ", " + std::to_string(increment) +
                " increments, " + std::to_string(total_iterations) + " Newton iterations, " +
                std::to_string(log.elapsed()) + " s\n");
      return {summary};
    }

    void
    Problem::postprocess(nlohmann::json &summary, const Vector<double> &velocity)
    {
      const double d = scale.d;
      // Nodal profile along the vertical edge x = y = 0: depth z, v_x / v_wall, g.
      struct NodeValues
      {
        double v = 0., g = 0., u = 0.;
      };
      std::map<double, NodeValues> by_depth;
      std::vector<Point<dim>> support(dof_handler.n_dofs());
      DoFTools::map_dofs_to_support_points(MappingQ1<dim>(), dof_handler, support);
      for (types::global_dof_index i = 0; i < support.size(); ++i)
        {
          const Point<dim> &x = support[i];
          if (x[0] > 1e-9 * scale.h || x[1] > 1e-9 * scale.h)
            continue;
          auto &entry = by_depth[x[2]];
          if (dof_component[i] == 0)
            {
              entry.v = velocity[i] / scale.v_wall;
              entry.u = U[i] / d;
            }
          else if (dof_component[i] == dim)
            entry.g = U[i];
        }
      std::vector<double> z, v, g, u;
      for (const auto &[depth, node] : by_depth)
        {
          z.push_back(depth / d);
          v.push_back(node.v);
          g.push_back(node.g * std::sqrt(d / prm.material.G)); // g sqrt(d / G), dimensionless
          u.push_back(node.u);
        }
      // W: the depth where v has decayed to v_wall / e (Henann 6.1).
      double W = z.back();
      for (unsigned int i = 1; i < z.size(); ++i)
        if (v[i] <= std::exp(-1.) && v[i - 1] > std::exp(-1.))
          {
            W = z[i - 1] + (z[i] - z[i - 1]) * (v[i - 1] - std::exp(-1.)) / (v[i - 1] - v[i]);
            break;
          }
      summary["shear_band_width_over_d"] = W;

      std::vector<std::string>         header  = {"z_over_d", "v_over_v_wall", "g_sqrt_d_over_G", "u_x_over_d"};
      std::vector<std::vector<double>> columns = {z, v, g, u};
      if (prm.output.reference == "finite difference")
        {
          postprocess::LinearShearGravity1d fd;
          fd.material         = prm.material.nonlocal;
          fd.phi              = prm.material.phi;
          fd.G                = prm.material.G;
          fd.P_wall           = scale.P_wall;
          fd.depth            = scale.depth;
          fd.h                = 0.01 * d;
          const auto profile  = postprocess::solve_linear_shear_gravity_for_speed(fd, scale.v_wall);
          std::vector<double> v_fd;
          double              worst = 0.;
          for (unsigned int i = 0; i < z.size(); ++i)
            {
              // the FD grid divides the depth, so node depths fall on or between grid points
              const double s   = z[i] * d / (profile.x[1] - profile.x[0]);
              const auto   k   = std::min<std::size_t>(static_cast<std::size_t>(s), profile.x.size() - 2);
              const double t   = s - k;
              const double vfd = ((1. - t) * profile.v[k] + t * profile.v[k + 1]) / profile.v_wall;
              v_fd.push_back(vfd);
              worst = std::max(worst, std::abs(vfd - v[i]));
            }
          header.push_back("v_over_v_wall_reference");
          columns.push_back(v_fd);
          summary["reference"] = {{"method", "finite difference of (90), 0.01 d grid"},
                                  {"mu_wall", profile.mu_wall},
                                  {"shear_band_width_over_d", profile.shear_band_width / d},
                                  {"max_velocity_difference_over_v_wall", worst},
                                  {"mu_wall_relative_difference", std::abs(summary["mu_wall"].get<double>() / profile.mu_wall - 1.)},
                                  {"shear_band_width_relative_difference", std::abs(W / (profile.shear_band_width / d) - 1.)}};
        }
      out.write_csv("profiles/velocity.csv", header, columns);

      // Quadrature-point fields averaged per brick, at the brick centres: mu, p, g_loc.
      std::vector<double> zc, mu, p, gloc;
      for (const auto &cell : tria.active_cell_iterators())
        {
          const auto &pts = points[cell->active_cell_index()];
          double      m = 0., pp = 0., gl = 0.;
          for (const auto &pt : pts)
            {
              m += pt.mu / pts.size();
              pp += pt.p / pts.size();
              gl += pt.g_loc / pts.size();
            }
          zc.push_back(cell->center()[2] / d);
          mu.push_back(m);
          p.push_back(pp / (scale.body_force * d));
          gloc.push_back(gl * std::sqrt(d / prm.material.G));
        }
      out.write_csv("profiles/stress.csv", {"z_over_d", "mu", "p_over_phi_rho_s_G_d", "g_loc_sqrt_d_over_G"},
                    {zc, mu, p, gloc});
    }

    void
    Problem::write_vtu(const Vector<double> &velocity)
    {
      DataOut<dim> data_out;
      data_out.attach_dof_handler(dof_handler);
      std::vector<std::string> names(dim, "displacement");
      names.push_back("g");
      std::vector<DataComponentInterpretation::DataComponentInterpretation> kinds(
        dim, DataComponentInterpretation::component_is_part_of_vector);
      kinds.push_back(DataComponentInterpretation::component_is_scalar);
      data_out.add_data_vector(U, names, DataOut<dim>::type_dof_data, kinds);
      std::vector<std::string> vnames(dim, "velocity");
      vnames.push_back("dg_dt");
      data_out.add_data_vector(velocity, vnames, DataOut<dim>::type_dof_data, kinds);
      Vector<float> mu(tria.n_active_cells()), p(tria.n_active_cells()), tau(tria.n_active_cells()),
        gamma_dot(tria.n_active_cells());
      for (unsigned int c = 0; c < points.size(); ++c)
        for (const auto &pt : points[c])
          {
            mu[c] += pt.mu / points[c].size();
            p[c] += pt.p / points[c].size();
            tau[c] += pt.tau / points[c].size();
            gamma_dot[c] += pt.gamma_dot_p / points[c].size();
          }
      data_out.add_data_vector(mu, "mu");
      data_out.add_data_vector(p, "pressure");
      data_out.add_data_vector(tau, "equivalent_shear_stress");
      data_out.add_data_vector(gamma_dot, "plastic_shear_rate");
      data_out.build_patches();
      std::ostringstream vtu;
      data_out.write_vtu(vtu);
      out.write_text("solution-0000.vtu", vtu.str());
      std::ostringstream pvd;
      DataOutBase::write_pvd_record(pvd, {{0., std::string("solution-0000.vtu")}});
      out.write_text("solution.pvd", pvd.str());
    }
  } // namespace

  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log)
  {
    Problem problem(parameters, output, log);
    return problem.run();
  }
} // namespace granflow::ngf
