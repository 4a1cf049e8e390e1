#include "models/ngf/ngf_model.h"

#include "core/errors.h"
#include "core/interrupt.h"
#include "core/run_report.h"
#include "fem/mapping_without_cell_similarity.h"
#include "models/ngf/ngf_element.h"
#include "postprocess/nonlocal_1d.h"
#include "solvers/newton.h"
#include "solvers/umfpack_solver.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/work_stream.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace granflow::ngf
{
  namespace
  {
    using namespace dealii;

    struct NewtonRecord
    {
      unsigned int increment, iteration;
      double       R_u, R_g;
      /// the full Newton correction from this iterate (before any line search and the g >= 0
      /// projection), L_inf relative to the field's L_inf (NaN where none was computed: the last
      /// iterate of an attempt)
      double dU_u = std::numeric_limits<double>::quiet_NaN(), dU_g = dU_u;
    };

    /// The value at distance 0 (the driven wall) of a field known at the element centres at
    /// distances x: extrapolated linearly from the two nearest. Nothing with fewer than two.
    std::optional<double>
    extrapolate_to_wall(const std::vector<double> &x, const std::vector<double> &value)
    {
      std::vector<std::pair<double, double>> by_x;
      for (std::size_t i = 0; i < x.size(); ++i)
        by_x.emplace_back(x[i], value[i]);
      std::sort(by_x.begin(), by_x.end());
      if (by_x.size() < 2)
        return std::nullopt;
      const auto [x0, v0] = by_x[0];
      const auto [x1, v1] = by_x[1];
      return v0 - x0 * (v1 - v0) / (x1 - x0);
    }

    solvers::NewtonOptions
    newton_options(const SolverParameters &s, Logger &log)
    {
      solvers::NewtonOptions o;
      o.tolerance           = s.tolerance;
      o.max_iterations      = s.max_iterations;
      o.reuse_factorization = s.reuse_factorization;
      o.log                 = &log.table();
      return o;
    }

    /// The remedy the local model's warnings give. In the rate-independent regime its flow
    /// collapses into the first element at every resolution (Henann & Kamrin 2016, Fig. 7b; mu(I)
    /// is ill posed at low I, Barker et al. 2015): the column at v_wall = 1e-3 refined from h = d /
    /// 3 to d / 90 kept its band in one element (W = 0.63 h), mu_wall 0.391, 0.382, 0.372, 0.388.
    /// (W/d 0.211, 0.070, 0.051 at d / 3, d / 9, d / 27: the band's element count is no test, it
    /// reaches 1.4 at d / 27.) At higher rates refining does resolve it (v_wall = 0.1: 1.5
    /// elements at d / 3, 4.4 at d / 9, W/d 0.511 and 0.494, mu_wall the same to 3e-5).
    constexpr const char *local_localises =
        "refine Geometry/Element size; if W/d keeps shrinking with h, the local model is "
        "localising, as it does at low rates (Henann & Kamrin Fig. 7), and Solver/Fluidity = "
        "nonlocal resolves the band";

    /// One run of a geometry: dim = 3 are bricks (the shear column of Henann 6.1, the annulus slice
    /// of 6.3), dim = 2 an annulus section of generalized-axisymmetric quads (6.2, 6.3). Nodal
    /// unknowns: (u_x, u_y, u_z, g) or (u_r, u_z, theta, g).
    template <int dim> class Problem
    {
    public:
      Problem(const Parameters &prm, OutputDirectory &out, Logger &log);
      Results
      run();

    private:
      const bool column; // the shear column (6.1)
      const bool row;    // the annulus row (6.2, no gravity)
      const bool slice;  // the 3D annulus slice (6.3)
      // boundary ids: of GridGenerator::subdivided_hyper_rectangle with colorize = true for the
      // column and the quad section; the slice is renumbered to the quad's ids plus its two
      // periodic faces
      const types::boundary_id            wall_id;        // the driven wall (z = 0, R = R_i)
      const types::boundary_id            outer_id;       // z = depth, R = R_o
      static constexpr types::boundary_id floor_id   = 2; // Z = 0 (annulus)
      static constexpr types::boundary_id top_id     = 3; // Z = H (annulus)
      static constexpr types::boundary_id first_face = 4, second_face = 5; // theta = 0, slice angle
      static constexpr unsigned int       twist = 2;                       // theta component (quad)

      types::boundary_id
      boundary_id(const std::string &name) const;
      void
      make_mesh();
      void
      setup_system();
      /// jacobian_csr's pattern (the sorted columns of `jacobian`'s) and csr_position.
      void
      index_jacobian_csr();
      /// dU = -J^-1 residual with the factorisation of the current Jacobian if `factorize`, else
      /// with the last one; false if the Jacobian is singular.
      bool
      solve_with_jacobian(Vector<double> &dU, bool factorize);
      /// Periodicity, the Dirichlet conditions of the geometry at wall displacement `u_wall` (an
      /// arc length for the annulus) and the fluidity Dirichlet values; `homogeneous` gives the
      /// constraints of the Newton corrections.
      void
      make_constraints(AffineConstraints<double> &c, double u_wall, bool homogeneous) const;
      /// The slice's rotated periodicity: the nodes of the face at the slice angle are the images
      /// of those at Theta = 0 under the rotation Q about z, with u = Q u_0 and g = g_0 there.
      void
      add_rotated_periodicity(AffineConstraints<double> &c) const;
      /// L_inf norms of the displacement and fluidity residuals and the scales that normalise them.
      struct ResidualNorms
      {
        double u = 0., g = 0., u_scale = 0., g_scale = 0.;
        double
        R_u(double scale) const
        {
          return scale > 0. ? u / scale : u;
        }
        double
        R_g(double scale) const
        {
          return scale > 0. ? g / scale : g;
        }
      };
      /// Assembles r (constrained rows zeroed) and, if asked, J.
      ResidualNorms
      assemble(double dt, bool with_jacobian);
      /// (35): the wall pressure and the fluidity flux zeta on the faces of `cell`.
      void
      add_boundary_loads(const typename DoFHandler<dim>::active_cell_iterator &cell,
                         FEFaceValues<dim> &face, Vector<double> &r_local) const;
      /// L_inf norms of the assembled residual's two fields (NaN if any entry is), scales unset.
      ResidualNorms
      residual_norms() const;
      class Increment;
      /// One increment's Newton iterations (solvers::NewtonSolver); false: not converged.
      bool
      newton(double dt, unsigned int increment, unsigned int &iterations);

      /// Name of p / scale.P_wall in the VTU and stress.csv: P_wall for the column and the annulus
      /// row, the hydrostatic pressure at the floor phi rho_s G H for the annulus (Fig. 6).
      std::string
      pressure_name() const
      {
        return column || row ? "p_over_P_wall" : "p_over_phi_rho_s_G_H";
      }
      /// mu_wall from the reactions where the wall motion is prescribed (Henann 6.1, 6.2).
      double
      wall_stress_ratio() const;
      /// Nodal velocity (v_x, v_y, v_z, dg/dt) or (v_r, v_z, v_theta = r dtheta/dt, dg/dt).
      Vector<double>
      velocity(double dt) const;
      /// What march() leaves of a run: the last converged shear increment's wall displacement,
      /// mu_wall, velocity and rate, the Newton counts, the state at the start of the steadiness
      /// window, the history, and why the run stopped short (`failure`, empty if it completed).
      struct RunState
      {
        double         u_wall = 0., mu_wall = 0.;
        double         last_step = 0.; // wall displacement of the last shear increment
        unsigned int   increment = 0, total_iterations = 0, cuts = 0, max_iterations = 0;
        Vector<double> v, rate;
        bool           loading     = true;  // no increment has converged
        bool           interrupted = false; // failure: a stop request (core/interrupt.h)
        std::string    failure;             // set when an increment cannot be completed
        // the last state at or before the start of the steadiness window (u_wall_window < 0:
        // none)
        double              u_wall_window = -1., mu_wall_window = 0.;
        Vector<double>      v_window;
        std::vector<double> h_disp, h_mu, h_iter; // per increment: the history.csv columns
      };
      /// The increments: the loading step, then the wall's motion to Loading/Wall displacement
      /// (or rotation), with increments adapted to Newton and cut when it fails.
      RunState
      march();
      /// Wall displacement over which steadiness is judged at the end of the run.
      double
      steady_window() const;
      /// summary.json's description of the run: case, mesh, loading, mu_wall, Newton counts.
      nlohmann::json
      describe_run(const RunState &s) const;
      /// summary.json's `steady_state` and, if the run is not steady, why.
      std::pair<nlohmann::json, std::string>
      judge_steadiness(const RunState &s) const;
      /// Warnings on how the run ended: a Newton failure, no steady state, large increments.
      void
      warn_about_run(const RunState &s, bool steady, const std::string &why_not_steady);
      void
      warn_if_below_mu_s(double mu_wall);
      /// The 3D cells' volume-change spread, and the slice's warning when it drifts.
      void
      report_distortion(nlohmann::json &summary);
      /// The largest pressure over the smaller elastic modulus: the scale of the elastic strains.
      double
      elastic_strain_scale() const;
      /// Whether elastic_strain_scale() is outside [1e-9, 1e-2], where the model and the solver are
      /// meant to work.
      bool
      outside_elastic_range() const;
      void
      warn_if_outside_elastic_range();
      void
      predict(const Vector<double> &rate, double dt);
      std::string
      newton_failure(bool loading, double dt, double du, double u_wall) const;
      Vector<double>
      increment_rate(double dt) const;
      /// The wall-parallel velocity that steadiness is judged on, per dof (0 elsewhere): v_x of the
      /// column, r dtheta/dt of the quad section, and for the slice (v_r, r dphi/dt) of each node
      /// from the increment's rate, which a steady flow keeps as its nodes turn about z (their
      /// Cartesian velocities turn with them: by the angle turned, 0.007 over 0.4 degrees).
      Vector<double>
      steady_velocity(const Vector<double> &v, const Vector<double> &rate) const;
      /// The speed parallel to the driven wall at the node whose first dof (x or r) is i: v_x
      /// (column), v_theta (quad section), v_theta at the node's current angle (slice).
      double
      wall_parallel_speed(types::global_dof_index i, const Vector<double> &v) const;
      /// The largest relative difference, over the cells and their Gauss points, between the
      /// volume change det F of the current geometry at a Gauss point and at the cell's centroid
      /// (where F-bar takes it); 3D only. It is 0 where the cells deform affinely (the column's
      /// simple shear) and grows as the slice's cells are sheared around the arc.
      double
      volume_change_spread() const;
      void
      write_histories(const std::vector<double> &wall_displacement,
                      const std::vector<double> &mu_wall,
                      const std::vector<double> &newton_iterations);
      /// The finite-difference solution of (90) or (92) if Output/Reference asks for it; computed
      /// before the solve, so that parameters it cannot handle end the run at once as bad input.
      void
      compute_reference();
      void
      /// The profiles, W, the wall pressure and their warnings (those on the band and the wall
      /// pressure only for a run that ended steady: `finished`).
      postprocess(nlohmann::json &summary, const Vector<double> &velocity, bool finished);
      /// The nodal profile across the band from the driven wall (distance x / d, v / v_wall, g in
      /// units of g_unit(), and u_x / d or the angle of rotation), ordered from the wall.
      struct WallProfile
      {
        std::vector<double> x, v, g, u;
      };
      /// For the annulus with gravity, along the layer of nodes at height `level` (reference
      /// configuration); the surface profile is at level = H. Ignored by the column and the row.
      WallProfile
      wall_profile(const Vector<double> &v, double level) const;
      /// The annulus with gravity's profile at `depth` below the free surface: the FE field
      /// between the two layers of nodes around it, linear along the vertical element edges.
      WallProfile
      profile_at_depth(const Vector<double> &v, double depth) const;
      /// Output/Profile depths: profiles/velocity_at_depth_*.csv and their W/d in the summary.
      void
      write_profiles_at_depths(nlohmann::json &summary, const Vector<double> &v,
                               const std::vector<std::string> &header);
      /// The coordinate that runs across the band: z for the column, r for the annuli.
      unsigned int
      along() const
      {
        return column ? dim - 1 : 0; // (the column is 3D)
      }
      double
      g_unit() const;
      /// W/d into summary.json, and the warnings on a band the mesh or the domain does not
      /// resolve (those only for a `finished` run); returns W/d (NaN if the flow does not decay).
      double
      judge_band(nlohmann::json &summary, const WallProfile &profile, bool finished);
      /// summary.json's `reference`; returns the reference's v / v_wall at the profile's nodes.
      std::vector<double>
      compare_with_reference(nlohmann::json &summary, const WallProfile &profile, double W) const;
      /// The pressure at the driven wall and mu_wall_local (column, annulus row), from the
      /// element centres' distances xc and pressures p.
      void
      report_wall_pressure(nlohmann::json &summary, const std::vector<double> &xc,
                           const std::vector<double> &p, bool finished);
      /// The annulus with gravity: the mean pressure along the driven wall over the hydrostatic
      /// phi rho_s G H / 2 that mu_wall is taken over (wall_pressure_over_hydrostatic), from the
      /// depth-averaged pressures p_column (over P_wall = phi rho_s G H) of the radial columns of
      /// elements at distances xc (in d), and mu_wall_local; a warning when it is off by 0.2 %.
      void
      report_wall_pressure_with_gravity(nlohmann::json &summary, const std::vector<double> &xc,
                                        const std::vector<double> &p_column, bool finished);
      void
      compare_rate_dependent_part(nlohmann::json &summary, double mu_wall) const;
      /// What a warning on an unresolved band advises: refining, or for the local model
      /// `local_localises`.
      const char *
      refine_advice() const
      {
        return prm.solver.fluidity == "local" ? local_localises : "refine Geometry/Element size";
      }
      void
      write_vtu(const Vector<double> &velocity);

      const Parameters &prm;
      const Scales      scale;
      OutputDirectory  &out;
      Logger           &log;
      RunReport         report{log, out, "ngf"}; // after log and out, which it refers to
      NonlocalElement   element;

      Triangulation<dim>                          tria;
      FESystem<dim>                               fe;
      DoFHandler<dim>                             dof_handler;
      AffineConstraints<double>                   newton_constraints;
      SparsityPattern                             sparsity;
      SparseMatrix<double>                        jacobian;
      Vector<double>                              U, U_n, residual, unconstrained_residual;
      std::vector<ElementShape>                   shapes; // per cell
      std::vector<std::vector<rheology::Tensor2>> Fp_n;   // per cell, per quadrature point
      std::vector<std::vector<rheology::NonlocalPointUpdate>> points; // last evaluated state
      std::vector<std::pair<types::boundary_id, double>>      g_dirichlet, g_neumann;
      std::vector<NewtonRecord>                               newton_log;
      std::vector<unsigned int> dof_component; // 0-2 displacement-type, 3: g
      double                    assembly_seconds = 0., solve_seconds = 0.;
      // Sum over all nodes of the bulk part of the fluidity residual (34)_2 at the last assembly,
      // int (g - g_loc) / xi^2 dv (sum_A N^A = 1, sum_A grad N^A = 0): at a converged state, the
      // net fluidity that the boundary conditions feed into the body (negative: they take it
      // out; (23) has no time derivative).
      double                                        boundary_fluidity_supply = 0.;
      // The last factorised Jacobian, copied into CSR with sorted columns (UMFPACK's order) through
      // csr_position, and factorised without UMFPACK's iterative refinement (setup_system()); the
      // symbolic analysis, of the first Jacobian, is kept for the run.
      solvers::CsrMatrix        jacobian_csr;
      std::vector<unsigned int> csr_position; // of each entry of `jacobian`, in its storage order
      solvers::UmfpackSolver    factorization;
      solvers::NewtonSolver<Vector<double>>         newton_solver;
      std::vector<Point<dim>>   dof_point; // reference position of each dof
      std::optional<postprocess::Nonlocal1dProfile> reference; // Output/Reference
    };

    template <int dim>
    Problem<dim>::Problem(const Parameters &prm, OutputDirectory &out, Logger &log)
        : column(prm.geometry.shape == "shear column")
        , row(prm.geometry.shape == "annulus row")
        , slice(prm.geometry.shape == "annulus slice")
        , wall_id(column ? 4 : 0)
        , outer_id(column ? 5 : 1)
        , prm(prm)
        , scale(prm.scales())
        , out(out)
        , log(log)
        , element(dim == 3 ? Kinematics::brick : Kinematics::axisymmetric, prm.material.elastic,
                  prm.material.nonlocal, prm.solver.fluidity == "local")
        , fe(FE_Q<dim>(1), 4)
        , dof_handler(tria)
        , newton_solver(newton_options(prm.solver, log))
    {
      // names were checked against the geometry by Parameters::validate()
      for (const auto &[name, value] : prm.fluidity_dirichlet())
        g_dirichlet.emplace_back(boundary_id(name), value);
      for (const auto &[name, value] : prm.fluidity_neumann())
        g_neumann.emplace_back(boundary_id(name), value);
    }

    template <int dim>
    types::boundary_id
    Problem<dim>::boundary_id(const std::string &name) const
    {
      const std::map<std::string, types::boundary_id> ids =
          column
              ? std::map<std::string, types::boundary_id>{{"wall", wall_id}, {"bottom", outer_id}}
              : std::map<std::string, types::boundary_id>{{"inner wall", wall_id},
                                                          {"outer wall", outer_id},
                                                          {"bottom", floor_id},
                                                          {"top", top_id}};
      return ids.at(name);
    }

    template <int dim>
    void
    Problem<dim>::make_mesh()
    {
      if constexpr (dim == 3)
        {
          if (column)
            GridGenerator::subdivided_hyper_rectangle(
                tria, {scale.n_2, scale.n_2, scale.n_1}, Point<3>(0., 0., 0.),
                Point<3>(scale.h, scale.h, scale.depth), true);
          else
            {
              // (R, Theta, Z) box mapped to the slice; ids: R_i 0, R_o 1, Theta = 0 -> 4, slice
              // angle -> 5, Z = 0 -> 2, Z = H -> 3 (the quad section's ids plus the two periodic
              // faces)
              const double angle = prm.geometry.slice_angle * M_PI / 180.;
              GridGenerator::subdivided_hyper_rectangle(tria, {scale.n_1, 1U, scale.n_2},
                                                        Point<3>(scale.R_i, 0., 0.),
                                                        Point<3>(scale.R_o, angle, scale.H), true);
              for (const auto &face : tria.active_face_iterators())
                if (face->at_boundary())
                  {
                    const types::boundary_id id = face->boundary_id();
                    face->set_boundary_id(id == 2   ? 4
                                          : id == 3 ? 5
                                          : id == 4 ? 2
                                          : id == 5 ? 3
                                                    : id);
                  }
              GridTools::transform(
                  [](const Point<3> &p) {
                    return Point<3>(p[0] * std::cos(p[1]), p[0] * std::sin(p[1]), p[2]);
                  },
                  tria);
            }
        }
      else
        GridGenerator::subdivided_hyper_rectangle(tria, {scale.n_1, scale.n_2},
                                                  Point<2>(scale.R_i, 0.),
                                                  Point<2>(scale.R_o, scale.H), true);
    }

    template <int dim>
    void
    Problem<dim>::index_jacobian_csr()
    {
      const std::size_t n = jacobian.m();
      jacobian_csr        = solvers::CsrMatrix();
      jacobian_csr.n_rows = jacobian_csr.n_cols = n;
      jacobian_csr.row_start.assign(1, 0);
      jacobian_csr.column.reserve(jacobian.n_nonzero_elements());
      csr_position.assign(jacobian.n_nonzero_elements(), 0);
      std::vector<std::pair<unsigned int, unsigned int>> row; // (column, storage index)
      unsigned int                                       k = 0;
      for (std::size_t i = 0; i < n; ++i)
        {
          row.clear();
          for (auto entry = jacobian.begin(i); entry != jacobian.end(i); ++entry)
            row.emplace_back(entry->column(), k++);
          std::sort(row.begin(), row.end());
          for (const auto &[column, index] : row)
            {
              csr_position[index] = jacobian_csr.column.size();
              jacobian_csr.column.push_back(static_cast<int>(column));
            }
          jacobian_csr.row_start.push_back(static_cast<int>(jacobian_csr.column.size()));
        }
      jacobian_csr.value.assign(jacobian_csr.column.size(), 0.);
    }

    template <int dim>
    bool
    Problem<dim>::solve_with_jacobian(Vector<double> &dU, const bool factorize)
    {
      const auto start = std::chrono::steady_clock::now();
      try
        {
          if (factorize)
            {
              unsigned int k = 0;
              for (std::size_t i = 0; i < jacobian.m(); ++i)
                for (auto entry = jacobian.begin(i); entry != jacobian.end(i); ++entry)
                  jacobian_csr.value[csr_position[k++]] = entry->value();
              factorization.factorize(jacobian_csr);
            }
          const std::vector<double> b(residual.begin(), residual.end());
          std::vector<double>       x;
          factorization.solve(x, b);
          dU.reinit(x.size(), true);
          std::copy(x.begin(), x.end(), dU.begin());
        }
      catch (const solvers::SingularMatrix &)
        {
          return false; // UMFPACK's other failures (out of memory) propagate: no increment cures
                        // them
        }
      solve_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      dU *= -1.;
      newton_constraints.distribute(dU);
      return true;
    }

    template <int dim>
    void
    Problem<dim>::setup_system()
    {
      dof_handler.distribute_dofs(fe);
      dof_component.resize(dof_handler.n_dofs());
      dof_point.resize(dof_handler.n_dofs());
      DoFTools::map_dofs_to_support_points(MappingQ1<dim>(), dof_handler, dof_point);
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
            dof_component[dofs[i]] = fe.system_to_component_index(i).first;
        }
      // The velocity of the quad (v_theta = r dtheta/dt), the slice's predictor and its moment
      // address the dofs of a node as i, i + 1, ...: the four dofs of a node must be numbered
      // together, in component order (deal.II's default for a single-base FESystem).
      for (types::global_dof_index i = 0; i < dof_handler.n_dofs(); ++i)
        if (dof_component[i] == 0)
          for (unsigned int c = 1; c < 4; ++c)
            AssertThrow(i + c < dof_handler.n_dofs() && dof_component[i + c] == c &&
                            dof_point[i + c] == dof_point[i],
                        ExcMessage("ngf: the dofs of a node are expected to be numbered together"));
      make_constraints(newton_constraints, 0., true);
      DynamicSparsityPattern dsp(dof_handler.n_dofs());
      DoFTools::make_sparsity_pattern(dof_handler, dsp, newton_constraints, false);
      sparsity.copy_from(dsp);
      jacobian.reinit(sparsity);
      // Bad input like dp's guard of the same limit (exit 2), not an internal error.
      if (sparsity.n_nonzero_elements() >=
          static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw InputError(prm.case_file, "Geometry/Element size",
                         "the mesh's Jacobian has " +
                             std::to_string(sparsity.n_nonzero_elements()) +
                             " nonzeros, more than the 32-bit indices of the linear solver "
                             "(UMFPACK) address: expected a coarser mesh");
      index_jacobian_csr();
      // Newton corrects an inexact step by itself (it also steps with an old Jacobian): UMFPACK's
      // iterative refinement, 2 steps by default, cost 30 % of the linear solves on the annulus
      // with gravity and changed no iterate (docs/ngf.md, "Newton: the driver").
      factorization.set_refinement_steps(0);
      for (auto *v : {&U, &U_n, &residual, &unconstrained_residual})
        v->reinit(dof_handler.n_dofs());

      // Reference-configuration shape data, once: Q1 with the 2^dim Gauss rule (full integration,
      // F-bar against locking) and the centroid values of F-bar. Gradients as 3-vectors: (X, Y, Z)
      // for the brick, (R, Theta, Z) with a zero Theta component for the quad.
      const FE_Q<dim> scalar(1);
      QGauss<dim>     quadrature(2);
      Point<dim>      middle;
      for (unsigned int i = 0; i < dim; ++i)
        middle[i] = 0.5;

      // Every cell evaluated afresh, whatever the number of threads
      // (fem/mapping_without_cell_similarity.h).
      const WithoutCellSimilarity<MappingQ, dim> mapping(1);

      FEValues<dim> values(mapping, scalar, quadrature,
                           update_values | update_gradients | update_JxW_values |
                               update_quadrature_points);
      FEValues<dim> centroid(mapping, scalar, Quadrature<dim>(middle),
                             update_values | update_gradients | update_quadrature_points);
      auto          three = [](const Tensor<1, dim> &t) {
        return dim == 3 ? Tensor<1, 3>({t[0], t[1], t[dim - 1]})
                                 : Tensor<1, 3>({t[0], 0., t[dim - 1]});
      };
      const unsigned int n_nodes = scalar.n_dofs_per_cell();
      shapes.resize(tria.n_active_cells());
      for (const auto &cell : tria.active_cell_iterators())
        {
          values.reinit(cell);
          centroid.reinit(cell);
          ElementShape &s = shapes[cell->active_cell_index()];
          s.N.assign(quadrature.size(), std::vector<double>(n_nodes));
          s.dN_dX.assign(quadrature.size(), std::vector<Tensor<1, 3>>(n_nodes));
          s.JxW.resize(quadrature.size());
          s.R.resize(quadrature.size());
          s.N_centroid.resize(n_nodes);
          s.dN_dX_centroid.resize(n_nodes);
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              s.JxW[q] = values.JxW(q);
              s.R[q]   = values.quadrature_point(q)[0];
              for (unsigned int a = 0; a < n_nodes; ++a)
                {
                  s.N[q][a]     = values.shape_value(a, q);
                  s.dN_dX[q][a] = three(values.shape_grad(a, q));
                }
            }
          for (unsigned int a = 0; a < n_nodes; ++a)
            {
              s.N_centroid[a]     = centroid.shape_value(a, 0);
              s.dN_dX_centroid[a] = three(centroid.shape_grad(a, 0));
            }
          s.R_centroid = centroid.quadrature_point(0)[0];
        }
      Fp_n.assign(tria.n_active_cells(),
                  std::vector<rheology::Tensor2>(quadrature.size(), unit_symmetric_tensor<3>()));
      points.assign(tria.n_active_cells(),
                    std::vector<rheology::NonlocalPointUpdate>(quadrature.size()));
    }

    template <int dim>
    void
    Problem<dim>::make_constraints(AffineConstraints<double> &c, const double u_wall,
                                   const bool homogeneous) const
    {
      c.clear();
      const double s   = homogeneous ? 0. : 1.;
      auto         fix = [&](types::boundary_id id, unsigned int component, double value) {
        VectorTools::interpolate_boundary_values(
                    dof_handler, id, Functions::ConstantFunction<dim>(s * value, 4), c,
                    fe.component_mask(FEValuesExtractors::Scalar(component)));
      };
      if (slice)
        {
          // 6.3 on the 3D slice: the inner wall turns rigidly about z (u = (Q(theta_w) - 1) x in x
          // and y), the outer wall is fixed in x and y, the floor in z; the grains slide freely
          // along z on the walls.
          const double theta_w = u_wall / scale.R_i;
          for (const unsigned int k : {0U, 1U})
            {
              VectorTools::interpolate_boundary_values(
                  dof_handler, wall_id,
                  VectorFunctionFromScalarFunctionObject<dim>(
                      [&, k](const Point<dim> &x) {
                        const double cs = std::cos(theta_w) - 1., sn = std::sin(theta_w);
                        return s * (k == 0 ? cs * x[0] - sn * x[1] : sn * x[0] + cs * x[1]);
                      },
                      k, 4),
                  c, fe.component_mask(FEValuesExtractors::Scalar(k)));
              fix(outer_id, k, 0.);
            }
          fix(floor_id, 2, 0.);
          add_rotated_periodicity(c);
        }
      else if constexpr (dim == 3)
        {
          std::vector<GridTools::PeriodicFacePair<typename DoFHandler<dim>::cell_iterator>>
              periodic;
          GridTools::collect_periodic_faces(dof_handler, 0, 1, 0, periodic);
          GridTools::collect_periodic_faces(dof_handler, 2, 3, 1, periodic);
          DoFTools::make_periodicity_constraints<dim, dim>(periodic, c);
          // Henann 6.1: fixed bottom; the wall moves along x and is free along z (loaded by
          // P_wall).
          for (unsigned int k = 0; k < 3; ++k)
            fix(outer_id, k, 0.);
          fix(wall_id, 0, u_wall);
          fix(wall_id, 1, 0.);
        }
      else
        {
          // 6.2 and 6.3: the inner wall turns without moving radially; the outer wall does not
          // turn.
          fix(wall_id, 0, 0.);
          fix(wall_id, twist, u_wall / scale.R_i);
          fix(outer_id, twist, 0.);
          if (row)
            {
              // 6.2: u_z = 0 in the whole model
              for (types::global_dof_index i = 0; i < dof_component.size(); ++i)
                if (dof_component[i] == 1 && !c.is_constrained(i))
                  c.add_line(i);
            }
          else
            {
              // 6.3: rough walls that the grains slide along freely in z; smooth floor (u_z = 0
              // only)
              fix(outer_id, 0, 0.);
              fix(floor_id, 1, 0.);
            }
        }
      for (const auto &[id, value] : g_dirichlet)
        fix(id, 3, value);
      if (prm.solver.fluidity == "local")
        for (types::global_dof_index i = 0; i < dof_component.size(); ++i)
          if (dof_component[i] == 3 && !c.is_constrained(i))
            c.add_line(i); // g = g_loc is a quadrature-point quantity; the nodal fluidity is unused
      c.close();
    }

    template <int dim>
    void
    Problem<dim>::add_rotated_periodicity(AffineConstraints<double> &c) const
    {
      const double angle = prm.geometry.slice_angle * M_PI / 180.;
      const double cs = std::cos(angle), sn = std::sin(angle);
      using Node = std::array<types::global_dof_index, 4>;
      auto key   = [&](const Point<dim> &x) {
        return std::make_pair(std::lround(std::hypot(x[0], x[1]) / scale.h * 1e6),
                                std::lround(x[dim - 1] / scale.h * 1e6));
      };
      std::map<std::pair<long, long>, Node> first, second;
      for (const auto i :
           DoFTools::extract_boundary_dofs(dof_handler, ComponentMask(), {first_face}))
        first[key(dof_point[i])][dof_component[i]] = i;
      for (const auto i :
           DoFTools::extract_boundary_dofs(dof_handler, ComponentMask(), {second_face}))
        second[key(dof_point[i])][dof_component[i]] = i;
      AssertThrow(first.size() == second.size(),
                  ExcMessage("the periodic faces of the slice do not match"));
      for (const auto &[where, slave] : second)
        {
          const Node &master = first.at(where);
          // rows of Q for (u_x, u_y, u_z, g)
          const double Q[4][4] = {
              {cs, -sn, 0., 0.}, {sn, cs, 0., 0.}, {0., 0., 1., 0.}, {0., 0., 0., 1.}};
          for (unsigned int k = 0; k < 4; ++k)
            {
              if (c.is_constrained(slave[k]))
                continue; // a wall condition, itself the rotated image of the master's
              c.add_line(slave[k]);
              for (unsigned int j = 0; j < 4; ++j)
                if (Q[k][j] != 0.)
                  c.add_entry(slave[k], master[j], Q[k][j]);
            }
        }
    }

    template <int dim>
    void
    Problem<dim>::add_boundary_loads(const typename DoFHandler<dim>::active_cell_iterator &cell,
                                     FEFaceValues<dim> &face, Vector<double> &r_local) const
    {
      // (35): external traction and fluidity flux, per unit reference area (per radian for the
      // annulus: dA = R dZ). The shear column's wall presses along +z on z = 0; the annulus
      // row's outer wall presses along -e_r.
      for (const unsigned int f : cell->face_indices())
        {
          if (!cell->face(f)->at_boundary())
            continue;
          const types::boundary_id id   = cell->face(f)->boundary_id();
          double                   zeta = 0.;
          for (const auto &[bid, value] : g_neumann)
            if (bid == id)
              zeta = value;
          const bool pressed = column ? id == wall_id : (id == outer_id && row);
          if (!pressed && zeta == 0.)
            continue;
          face.reinit(cell, f);
          for (unsigned int q = 0; q < face.get_quadrature().size(); ++q)
            {
              const double dA = face.JxW(q) * (dim == 3 ? 1. : face.quadrature_point(q)[0]);
              for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
                {
                  const unsigned int component = fe.system_to_component_index(i).first;
                  const double       N         = face.shape_value(i, q);
                  if (pressed && component == (column ? 2U : 0U))
                    r_local[i] += (column ? -1. : 1.) * N * scale.P_wall * dA;
                  if (component == 3)
                    r_local[i] -= N * zeta * dA;
                }
            }
        }
    }

    template <int dim>
    typename Problem<dim>::ResidualNorms
    Problem<dim>::residual_norms() const
    {
      ResidualNorms n;
      for (types::global_dof_index i = 0; i < residual.size(); ++i)
        if (!newton_constraints.is_constrained(i))
          {
            double &r = dof_component[i] == 3 ? n.g : n.u;
            // a NaN must propagate (std::max would drop it and report convergence)
            r = std::isfinite(residual[i]) ? std::max(r, std::abs(residual[i]))
                                           : std::numeric_limits<double>::quiet_NaN();
            if (std::isnan(r))
              return {r, r, 1., 1.};
          }
      return n;
    }

    template <int dim>
    typename Problem<dim>::ResidualNorms
    Problem<dim>::assemble(const double dt, const bool with_jacobian)
    {
      const auto start = std::chrono::steady_clock::now();
      if (with_jacobian)
        jacobian = 0.;
      residual                          = 0.;
      unconstrained_residual            = 0.;
      const unsigned int        n_nodes = GeometryInfo<dim>::vertices_per_cell;
      const unsigned int        n_dofs  = fe.n_dofs_per_cell();
      std::vector<unsigned int> kernel_index(n_dofs);
      for (unsigned int i = 0; i < n_dofs; ++i)
        {
          const auto [component, node] = fe.system_to_component_index(i);
          kernel_index[i]              = 4 * node + component;
        }
      QGauss<dim - 1> face_quadrature(2);

      // The elements are evaluated in parallel (WorkStream, one thread per core); each writes
      // only its own constitutive state points[c]. The copier adds into the global system
      // serially and in cell order, so the result does not depend on the number of threads.
      struct Scratch
      {
        Scratch(const FiniteElement<dim> &fe, const Quadrature<dim - 1> &q,
                const unsigned int n_nodes)
            : face(fe, q, update_values | update_JxW_values | update_quadrature_points)
        {
          in.u.resize(n_nodes);
          in.g.resize(n_nodes);
        }
        Scratch(const Scratch &other)
            : face(other.face.get_fe(), other.face.get_quadrature(), other.face.get_update_flags())
            , in(other.in)
        {
        }
        FEFaceValues<dim> face;
        ElementInput      in;
        ElementOutput     eo;
      };
      struct Copy
      {
        std::vector<types::global_dof_index> dofs;
        Vector<double>                       r_local;
        FullMatrix<double>                   J_local;
        double                               force_scale = 0., fluidity_scale = 0.;
        double                               fluidity_supply = 0.;
      };
      double force_scale = 0., fluidity_scale = 0., fluidity_supply = 0.;

      const auto worker = [&](const typename DoFHandler<dim>::active_cell_iterator &cell,
                              Scratch &scratch, Copy &copy) {
        ElementInput  &in = scratch.in;
        ElementOutput &eo = scratch.eo;
        copy.dofs.resize(n_dofs);
        copy.r_local.reinit(n_dofs);
        if (with_jacobian)
          copy.J_local.reinit(n_dofs, n_dofs);
        cell->get_dof_indices(copy.dofs);
        for (unsigned int i = 0; i < n_dofs; ++i)
          {
            const unsigned int k = kernel_index[i];
            if (k % 4 == 3)
              in.g[k / 4] = U[copy.dofs[i]];
            else
              in.u[k / 4][k % 4] = U[copy.dofs[i]];
          }
        const unsigned int c = cell->active_cell_index();
        in.Fp_n              = Fp_n[c];
        element.evaluate(shapes[c], in, with_jacobian, eo);
        points[c] = eo.points;

        copy.force_scale = copy.fluidity_scale = copy.fluidity_supply = 0.;
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            copy.force_scale = std::max(
                copy.force_scale, std::sqrt(eo.magnitude[4 * a] * eo.magnitude[4 * a] +
                                            eo.magnitude[4 * a + 1] * eo.magnitude[4 * a + 1] +
                                            eo.magnitude[4 * a + 2] * eo.magnitude[4 * a + 2]));
            copy.fluidity_scale = std::max(copy.fluidity_scale, eo.magnitude[4 * a + 3]);
            copy.fluidity_supply += eo.residual[4 * a + 3];
          }
        for (unsigned int i = 0; i < n_dofs; ++i)
          {
            copy.r_local[i] = eo.residual[kernel_index[i]];
            if (with_jacobian)
              for (unsigned int j = 0; j < n_dofs; ++j)
                copy.J_local(i, j) = eo.jacobian(kernel_index[i], kernel_index[j]);
          }

        add_boundary_loads(cell, scratch.face, copy.r_local);
      };
      const auto copier = [&](const Copy &copy) {
        force_scale    = std::max(force_scale, copy.force_scale);
        fluidity_scale = std::max(fluidity_scale, copy.fluidity_scale);
        fluidity_supply += copy.fluidity_supply;
        for (unsigned int i = 0; i < copy.dofs.size(); ++i)
          unconstrained_residual[copy.dofs[i]] += copy.r_local[i];
        if (with_jacobian)
          newton_constraints.distribute_local_to_global(copy.J_local, copy.r_local, copy.dofs,
                                                        jacobian, residual);
        else
          newton_constraints.distribute_local_to_global(copy.r_local, copy.dofs, residual);
      };
      Scratch sample(fe, face_quadrature, n_nodes); // dt and b_0 are the same for every element
      sample.in.dt = dt;
      // (27): gravity into the bed (+z) for the column, along -z for the annulus
      sample.in.body_force = Tensor<1, 3>({0., 0., column ? scale.body_force : -scale.body_force});
      WorkStream::run(dof_handler.begin_active(), dof_handler.end(), worker, copier, sample,
                      Copy());

      // Henann 6.1: L_inf norms of the assembled residuals, each normalised by an element-level
      // nodal contribution to it. The paper takes the average; here it is the largest magnitude of
      // the terms that make up an element's nodal residual: where the flow is confined to a few
      // elements (its onset near a free surface) the average over the mesh is mostly zeros and
      // would demand more than round-off allows.
      ResidualNorms n = residual_norms();
      if (std::isnan(n.u))
        return n;
      n.u_scale = force_scale;
      n.g_scale                = fluidity_scale;
      boundary_fluidity_supply = fluidity_supply;
      assembly_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return n;
    }

    /// The coupled residual (34) of one increment as solvers::NewtonSolver sees it: the fields
    /// are the displacement-type unknowns and the fluidity, normalised as R_u and R_g.
    template <int dim> class Problem<dim>::Increment : public solvers::NewtonProblem<Vector<double>>
    {
    public:
      Increment(Problem<dim> &p, const double dt)
          : p(p)
          , dt(dt)
      {
      }

      Vector<double> &
      iterate() override
      {
        return p.U;
      }

      solvers::FieldResiduals
      residual(const bool with_jacobian) override
      {
        const ResidualNorms n = p.assemble(dt, with_jacobian);
        return {{n.u, n.g}, {n.u_scale, n.g_scale}};
      }

      bool
      correction(Vector<double> &dU, const bool factorize) override
      {
        return p.solve_with_jacobian(dU, factorize);
      }

      std::vector<solvers::CorrectionSize>
      correction_sizes(const Vector<double> &dU) const override
      {
        std::vector<solvers::CorrectionSize> size(2, {0., 0.}); // displacement-type, fluidity
        for (types::global_dof_index i = 0; i < dU.size(); ++i)
          {
            auto &s     = size[p.dof_component[i] == 3 ? 1 : 0];
            s.change    = std::max(s.change, std::abs(dU[i]));
            s.magnitude = std::max(s.magnitude, std::abs(p.U[i]));
          }
        return size;
      }

      /// The fluidity is non-negative (Henann Section 2): iterates are projected onto g >= 0, so
      /// that an overshoot below zero does not switch the flow rule off (max(g, 0) in the update).
      void
      make_admissible(Vector<double> &U) override
      {
        for (types::global_dof_index i = 0; i < U.size(); ++i)
          if (p.dof_component[i] == 3 && U[i] < 0.)
            U[i] = 0.;
      }

    private:
      Problem<dim> &p;
      const double  dt;
    };

    template <int dim>
    bool
    Problem<dim>::newton(const double dt, const unsigned int increment, unsigned int &iterations)
    {
      Increment                  step(*this, dt);
      const solvers::NewtonStats stats = newton_solver.solve(step, increment);
      for (unsigned int k = 0; k < stats.history.size(); ++k)
        {
          const auto &it = stats.history[k];
          newton_log.push_back(
              {increment, k, it.residual[0], it.residual[1], it.correction[0], it.correction[1]});
        }
      iterations = stats.iterations;
      return stats.converged;
    }

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
      // (run time, wall displacement) of the increments of the last 10 s, for the progress
      // line's estimate of the time left
      std::deque<std::pair<double, double>> pace;
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
          unsigned int iterations = 0;
          if (!newton(dt, s.increment, iterations))
            {
              du *= 0.25;
              ++s.cuts;
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
          s.total_iterations += iterations;
          s.max_iterations = std::max(s.max_iterations, iterations);
          ++s.increment;
          s.loading = false;
          if (iterations <= 4)
            du = std::min(du * prm.solver.growth, prm.solver.max_increment * d);
          std::ostringstream p;
          p << "increment " << s.increment << ": wall displacement " << s.u_wall / d << " d of "
            << scale.u_end / d << ", mu_wall " << s.mu_wall << ", " << iterations
            << " Newton iterations";
          // The time left at the pace of the last 10 s, once the increments have reached
          // Solver/Max increment: while they grow (the yielding transient) the pace says little
          // of what is left.
          const double now    = log.elapsed();
          const bool   capped = du >= prm.solver.max_increment * d * (1. - 1e-12);
          if (!capped)
            pace.clear();
          pace.emplace_back(now, s.u_wall);
          while (pace.size() > 2 && pace.front().first < now - 10.)
            pace.pop_front();
          const double advanced = pace.back().second - pace.front().second;
          if (capped && advanced > 0. && now - pace.front().first >= 1.)
            p << ", about "
              << std::lround((scale.u_end - s.u_wall) / advanced * (now - pace.front().first))
              << " s left";
          log.progress(p.str());
          if (interrupt::requested())
            {
              s.interrupted = true;
              s.failure     = std::string("stopped by ") + interrupt::signal_name() +
                          " after increment " + std::to_string(s.increment - 1) + " (of a run to " +
                          std::to_string(scale.u_end / d) + " d)";
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
            dv = std::max(dv, std::abs(v_end[i] - s.v_window[i]) / scale.v_wall);
          // relative to the larger of the two (a mu_wall of exactly 0, a body not loaded at all,
          // is steady if it stays 0)
          const double scale_mu = std::max(std::abs(s.mu_wall), std::abs(s.mu_wall_window));
          const double dmu =
              scale_mu == 0. ? 0. : std::abs(s.mu_wall - s.mu_wall_window) / scale_mu;
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
          w << std::setprecision(3) << "Newton failed (see the log): ";
          if (s.loading)
            w << "no increment converged, not even the loading step (gravity and wall pressure "
                 "with the wall at rest); the fields are the unloaded start";
          else if (s.u_wall == 0.)
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
                             : ": run further (Loading/Wall displacement or Wall rotation) before "
                               "using mu_wall, W/d or the profiles as steady results"));
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
    Problem<dim>::warn_if_below_mu_s(const double mu_wall)
    {
      // Steady flow starts where mu >= mu_s (g_loc = 0 below it, (22)), and mu is largest at the
      // driven wall in every geometry here: below mu_s there, the mesh does not resolve the flow
      // at the wall (g = 0 there on coarse meshes, docs/ngf.md) or the body has not yielded.
      // Fluidity fed in through the boundaries (g_wall > 0 above the fluidity beside it, zeta > 0)
      // lets material flow below mu_s. The test therefore applies unless the boundaries feed
      // fluidity in, in net: a g_wall below the fluidity beside the wall takes fluidity out, like
      // g = 0, and a source elsewhere may not make up for it.
      const auto positive        = [](const auto &condition) { return condition.second > 0.; };
      const bool fluidity_source = std::any_of(g_dirichlet.begin(), g_dirichlet.end(), positive) ||
                                   std::any_of(g_neumann.begin(), g_neumann.end(), positive);
      const bool fed_by_boundaries = fluidity_source && boundary_fluidity_supply > 0.;
      if (fed_by_boundaries || mu_wall >= prm.material.nonlocal.mu_s)
        return;
      std::ostringstream w;
      w << "mu_wall = " << mu_wall << " is below mu_s = " << prm.material.nonlocal.mu_s
        << " at the driven wall: a steady flow needs mu >= mu_s where it starts, so either the "
           "body has not yielded, or the mesh does not resolve the flow at the wall";
      // (with homogeneous Neumann conditions only, the supply is zero to the Newton
      // tolerance, and its sign means nothing)
      const bool conditions =
          !g_dirichlet.empty() ||
          std::any_of(g_neumann.begin(), g_neumann.end(),
                      [](const auto &condition) { return condition.second != 0.; });
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
      {
        // Until the first increment, a signal ends the run at once: nothing to write yet.
        const interrupt::BeforeResults before_results(out.left_as_it_was());
        compute_reference();
        make_mesh();
        setup_system();
      }
      const double d = scale.d;
      log.print("ngf: " + prm.geometry.shape + ", " + std::to_string(tria.n_active_cells()) +
                (dim == 3 ? " bricks" : " generalized-axisymmetric quads") +
                ", h/d = " + std::to_string(scale.h / d) + ", " +
                std::to_string(dof_handler.n_dofs()) + " dofs\n");
      warn_if_outside_elastic_range();
      log.table() << "Newton iterations (R_u, R_g: normalised L_inf residuals, Henann 6.1)\n"
                  << std::setw(6) << "incr" << std::setw(6) << "iter" << std::setw(12) << "R_u"
                  << std::setw(12) << "R_g" << '\n';

      const RunState s             = march();
      nlohmann::json summary       = describe_run(s);
      const auto [steady, why_not] = judge_steadiness(s);
      summary["steady_state"]      = steady;
      const bool steady_flow       = steady.at("steady").template get<bool>();
      warn_about_run(s, steady_flow, why_not);
      report_distortion(summary);
      if (s.failure.empty())
        warn_if_below_mu_s(s.mu_wall);
      // The band's own warnings only for a run that reached a steady flow: before that, the
      // profile is a loading one ("not steady" says so).
      postprocess(summary, s.v, s.failure.empty() && steady_flow);
      if (prm.output.write_vtu)
        write_vtu(s.v);
      write_histories(s.h_disp, s.h_mu, s.h_iter);
      report.timings = {{"assembly_s", assembly_seconds}, {"linear_solve_s", solve_seconds}};
      summary["converged"]   = s.failure.empty();
      summary["interrupted"] = s.interrupted;
      report.finish(summary,
                    s.failure.empty()
                        ? ""
                        : s.failure + "; the last converged state (wall displacement " +
                              std::to_string(s.u_wall / d) + " d) is written to " + out.target() +
                              " (see log.txt)",
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
      const NewtonRecord *best = nullptr;
      for (auto r = newton_log.rbegin(); r != newton_log.rend(); ++r)
        {
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
    Problem<dim>::wall_parallel_speed(const types::global_dof_index i,
                                      const Vector<double>         &v) const
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
            spread = std::max(spread, std::abs(J(g) / J_c - 1.));
        }
      return spread;
    }

    /// history.csv (per increment) and newton.csv (per Newton iterate).
    template <int dim>
    void
    Problem<dim>::write_histories(const std::vector<double> &wall_displacement,
                                  const std::vector<double> &mu_wall,
                                  const std::vector<double> &newton_iterations)
    {
      std::vector<double> inc, it, ru, rg, cu, cg;
      for (const auto &r : newton_log)
        {
          inc.push_back(r.increment);
          it.push_back(r.iteration);
          ru.push_back(r.R_u);
          rg.push_back(r.R_g);
          cu.push_back(r.dU_u);
          cg.push_back(r.dU_g);
        }
      out.write_csv("history.csv", {"wall_displacement_over_d", "mu_wall", "newton_iterations"},
                    {wall_displacement, mu_wall, newton_iterations});
      out.write_csv("newton.csv",
                    {"increment", "iteration", "R_u", "R_g", "correction_u", "correction_g"},
                    {inc, it, ru, rg, cu, cg});
    }

    template <int dim>
    void
    Problem<dim>::compute_reference()
    {
      if (prm.output.reference != "finite difference")
        return;
      const double d = scale.d;
      try
        {
          reference = [&] {
            if (column)
              {
                postprocess::LinearShearGravity1d fd;
                fd.material = prm.material.nonlocal;
                fd.phi      = prm.material.phi;
                fd.G        = prm.material.G;
                fd.P_wall   = scale.P_wall;
                fd.depth    = scale.depth;
                fd.h        = 0.01 * d;
                return postprocess::solve_linear_shear_gravity_for_speed(fd, scale.v_wall);
              }
            else
              {
                postprocess::AnnularShear1d fd;
                fd.material = prm.material.nonlocal;
                fd.P_wall   = scale.P_wall;
                fd.R_i      = scale.R_i;
                fd.R_o      = scale.R_o;
                fd.h        = 0.01 * d;
                return postprocess::solve_annular_shear_for_speed(fd, scale.v_wall);
              }
          }();
        }
      catch (const std::exception &e)
        {
          throw InputError(prm.case_file, "Output/Reference",
                           "= finite difference: the 1D reduction cannot be solved for these "
                           "parameters (" +
                               std::string(e.what()) + "): expected none");
        }
    }

    template <int dim>
    typename Problem<dim>::WallProfile
    Problem<dim>::wall_profile(const Vector<double> &v, const double level) const
    {
      const double d = scale.d;
      // Nodal profile across the shear band, from the driven wall: along the edge x = y = 0 of the
      // column (depth z), along the bottom of the annulus row, along the layer Z = level of the
      // annulus (the free surface for level = H; for the slice: on its face Theta = 0, where
      // x = R).
      auto on_line = [&](const Point<dim> &x) {
        if (column)
          return x[0] < 1e-9 * scale.h && x[1] < 1e-9 * scale.h;
        if (row)
          return x[1] < 1e-9 * scale.H;
        return std::abs(x[dim - 1] - level) < 1e-9 * scale.H &&
               (!slice || std::abs(x[1]) < 1e-9 * scale.h);
      };
      struct NodeValues
      {
        double v = 0., g = 0., u = 0.;
      };
      std::map<double, NodeValues> by_distance;
      for (types::global_dof_index i = 0; i < dof_point.size(); ++i)
        {
          if (!on_line(dof_point[i]))
            continue;
          auto &node = by_distance[dof_point[i][along()] - (column ? 0. : scale.R_i)];
          if (dof_component[i] == 0)
            {
              node.v = wall_parallel_speed(i, v) / scale.v_wall;
              // u_x / d, the angle of rotation theta [rad] (quad), or the slice node's angle
              node.u = column  ? U[i] / d
                       : slice ? std::atan2(dof_point[i][1] + U[i + 1], dof_point[i][0] + U[i])
                               : U[i + twist];
            }
          else if (dof_component[i] == 3)
            node.g = U[i];
        }
      WallProfile profile;
      for (const auto &[distance, node] : by_distance)
        {
          profile.x.push_back(distance / d);
          profile.v.push_back(node.v);
          profile.g.push_back(node.g / g_unit());
          profile.u.push_back(node.u);
        }
      return profile;
    }

    template <int dim>
    typename Problem<dim>::WallProfile
    Problem<dim>::profile_at_depth(const Vector<double> &v, const double depth) const
    {
      // The annulus's mesh is structured: n_2 layers of elements of height H / n_2, each vertical
      // element edge joins two nodes at the same R, and the Q1 field is linear along it.
      const double dz = scale.H / scale.n_2;
      const double z  = std::clamp(scale.H - depth * scale.d, 0., scale.H);
      const auto   below =
          std::min<unsigned int>(static_cast<unsigned int>(std::floor(z / dz)), scale.n_2 - 1);
      const double t     = std::clamp(z / dz - below, 0., 1.);
      WallProfile  lower = wall_profile(v, below * dz);
      if (t < 1e-9)
        return lower;
      const WallProfile upper = wall_profile(v, (below + 1) * dz);
      if (t > 1. - 1e-9)
        return upper;
      AssertThrow(upper.x == lower.x, ExcInternalError()); // the same radial nodes
      for (std::size_t i = 0; i < lower.x.size(); ++i)
        {
          lower.v[i] += t * (upper.v[i] - lower.v[i]);
          lower.g[i] += t * (upper.g[i] - lower.g[i]);
          lower.u[i] += t * (upper.u[i] - lower.u[i]);
        }
      return lower;
    }

    template <int dim>
    void
    Problem<dim>::write_profiles_at_depths(nlohmann::json &summary, const Vector<double> &v,
                                           const std::vector<std::string> &header)
    {
      const std::vector<double> depths = prm.profile_depths();
      if (depths.empty())
        return;
      auto &list = summary["profiles_at_depth"] = nlohmann::json::array();
      for (const double depth : depths)
        {
          const WallProfile p = profile_at_depth(v, depth);
          const std::string file =
              "profiles/velocity_at_depth_" + profile_depth_name(depth) + ".csv";
          out.write_csv(file, header, {p.x, p.v, p.g, p.u});
          // The inner wall turns rigidly, so v / v_wall = 1 at its node at every depth.
          const double W = postprocess::shear_band_width(p.x, p.v, 1.);
          list.push_back(
              {{"depth_over_d", depth},
               {"file", file},
               {"shear_band_width_over_d", std::isfinite(W) ? nlohmann::json(W) : nullptr}});
        }
    }

    template <int dim>
    double
    Problem<dim>::g_unit() const
    {
      // g in units of sqrt(G / d) (with gravity) or sqrt(P_wall / (rho_s d^2)) (annulus row)
      return row ? std::sqrt(scale.P_wall / prm.material.nonlocal.rho_s) / scale.d
                 : std::sqrt(prm.material.G / scale.d);
    }

    template <int dim>
    double
    Problem<dim>::judge_band(nlohmann::json &summary, const WallProfile &profile,
                             const bool finished)
    {
      const auto &x = profile.x, &vel = profile.v;
      // W: the distance from the driven wall at which v has decayed to v_wall / e (Henann 6.1);
      // undefined (null, NaN in comparisons) if it never does.
      // x starts at the driven wall (x.front() = 0), where v / v_wall = 1
      const double W = postprocess::shear_band_width(x, vel, 1.);
      if (std::isnan(W))
        {
          if (finished)
            report.warn(
                "the velocity does not decay to v_wall / e across the domain: no shear band, "
                "shear_band_width_over_d is null (the body still loading elastically, or a band "
                "wider than the domain)");
          summary["shear_band_width_over_d"] = nullptr;
        }
      else
        {
          summary["shear_band_width_over_d"] = W;
          // Inside the first element, W is where the linear interpolation between the wall node
          // and the next one crosses v_wall / e: a property of the mesh (the local model's band,
          // docs/ngf.md, or a nonlocal band finer than the mesh).
          if (finished && W < scale.h / scale.d)
            {
              std::ostringstream w;
              w << "the shear band is narrower than one element (W/d = " << W
                << " < h/d = " << scale.h / scale.d
                << "): W/d is interpolated inside the first element and depends on the mesh; "
                << refine_advice();
              report.warn(w.str());
            }
          // A band of a few elements is resolved, but coarsely: in the shear column at
          // P_wall / (phi rho_s G d) = 0.5 (W = 1.8 h) mu_wall and W/d are 11 % off the FD
          // solution of (90), at 4 h (the default case) 0.02 % and 1.4 %; at 2.7 h the annulus's
          // surface velocity is 0.09 v_wall from a fine mesh's (docs/ngf.md).
          else if (finished && W < 3. * scale.h / scale.d)
            {
              std::ostringstream w;
              w << std::setprecision(3) << "the shear band spans only " << W * scale.d / scale.h
                << " elements (W/d = " << W << ", h/d = " << scale.h / scale.d
                << "): at fewer than 3, mu_wall, W/d and the profile carry discretisation errors "
                   "of several per cent (docs/ngf.md); "
                << refine_advice();
              report.warn(w.str());
            }
        }
      // A band that reaches the far boundary, where v = 0 is imposed, is shaped by the size of
      // the domain, not only by the material.
      if (finished && vel.size() >= 2 && std::abs(vel[vel.size() - 2]) > 0.01)
        {
          std::ostringstream w;
          w << "the flow reaches the far boundary: v / v_wall = " << vel[vel.size() - 2]
            << " one element from it (at " << x[x.size() - 2]
            << " d): the band is confined by the domain, and W/d and mu_wall depend on its size ("
            << (column ? "Geometry/Depth" : "Geometry/Gap") << ")";
          report.warn(w.str());
        }
      return W;
    }

    template <int dim>
    std::vector<double>
    Problem<dim>::compare_with_reference(nlohmann::json &summary, const WallProfile &profile,
                                         const double W) const
    {
      const double        d   = scale.d;
      const auto         &ref = *reference;
      std::vector<double> v_fd;
      double              worst = 0.;
      for (unsigned int i = 0; i < profile.x.size(); ++i)
        {
          // the FD grid divides the domain, so node positions fall on or between grid points
          const double s   = profile.x[i] * d / (ref.x[1] - ref.x[0]);
          const auto   k   = std::min<std::size_t>(static_cast<std::size_t>(s), ref.x.size() - 2);
          const double t   = s - k;
          const double vfd = ((1. - t) * ref.v[k] + t * ref.v[k + 1]) / ref.v_wall;
          v_fd.push_back(vfd);
          worst = std::max(worst, std::abs(vfd - profile.v[i]));
        }
      const double mu_wall = summary["mu_wall"].is_number()
                                 ? summary["mu_wall"].get<double>()
                                 : std::numeric_limits<double>::quiet_NaN();
      summary["reference"] = {
          {"method", column ? "finite difference of (90), 0.01 d grid"
                            : "finite difference of (92), exact Couette kinematics, 0.01 d grid"},
          {"mu_wall", ref.mu_wall},
          {"shear_band_width_over_d", ref.shear_band_width / d},
          {"max_velocity_difference_over_v_wall", worst},
          // signed: (FE - FD) / FD
          {"mu_wall_relative_difference", mu_wall / ref.mu_wall - 1.},
          {"shear_band_width_relative_difference", W / (ref.shear_band_width / d) - 1.}};
      return v_fd;
    }

    template <int dim>
    void
    Problem<dim>::report_wall_pressure(nlohmann::json &summary, const std::vector<double> &xc,
                                       const std::vector<double> &p, const bool finished)
    {
      // The pressure at the driven wall, extrapolated linearly from the two nearest element
      // centres (exact for the column's hydrostatic gradient). mu_wall is the wall shear stress
      // over the applied P_wall, as in the paper; the local ratio tau / p at the wall differs from
      // it where the mean pressure p there is not P_wall (the annulus: about 1.005 P_wall).
      const std::optional<double> extrapolated = extrapolate_to_wall(xc, p);
      if (!extrapolated || !summary["mu_wall"].is_number())
        return;
      const double p_wall                  = *extrapolated;
      const double mu_wall                 = summary["mu_wall"];
      summary["wall_pressure_over_P_wall"] = p_wall;
      summary["mu_wall_local"]             = mu_wall / p_wall;
      // The annulus row's inner wall is not pressed by a traction: the pressure there carries the
      // elastic hoop stress of the loading, which relaxes only slowly under shearing, and not at
      // all outside a band (the local model). 0.2 % is twice the steadiness tolerance of mu_wall.
      if (finished && !column && std::abs(p_wall - 1.) > 2e-3)
        {
          std::ostringstream w;
          w << "the mean pressure at the driven wall is " << p_wall
            << " P_wall, not the P_wall that the steady solution of (92) assumes: "
            << (p_wall > 1. ? "elastic stresses of the loading remain (they relax only slowly "
                              "under shearing: Loading/Wall rotation)"
                            : "at the default increments it is above P_wall (elastic stresses of "
                              "the loading that relax slowly); below it, look at the increment "
                              "size (Solver/Max increment)")
            << "; mu_wall, the wall's shear stress over P_wall as in the paper, includes "
               "this, mu_wall_local = tau / p = "
            << mu_wall / p_wall << " does not";
          report.warn(w.str());
        }
      if (summary.contains("reference"))
        compare_rate_dependent_part(summary, column ? mu_wall : mu_wall / p_wall);
    }

    template <int dim>
    void
    Problem<dim>::postprocess(nlohmann::json &summary, const Vector<double> &v, const bool finished)
    {
      const WallProfile profile = wall_profile(v, scale.H);
      const double      W       = judge_band(summary, profile, finished);

      // The columns of every profile; velocity.csv adds the surface's reference if asked.
      const std::vector<std::string> profile_header = {
          column ? "z_over_d" : "r_minus_R_i_over_d", "v_over_v_wall",
          row ? "g_d_sqrt_rho_s_over_P_wall" : "g_sqrt_d_over_G", column ? "u_x_over_d" : "theta"};
      std::vector<std::string>         header  = profile_header;
      std::vector<std::vector<double>> columns = {profile.x, profile.v, profile.g, profile.u};
      if (reference)
        {
          header.push_back("v_over_v_wall_reference");
          columns.push_back(compare_with_reference(summary, profile, W));
        }
      out.write_csv("profiles/velocity.csv", header, columns);
      write_profiles_at_depths(summary, v, profile_header);

      // Quadrature-point fields averaged per element, at the element centres (the line cells only).
      std::vector<double> xc, mu, p, gloc;
      // The annulus with gravity: p summed over each radial column of elements, all of one height.
      std::map<unsigned int, std::pair<double, unsigned int>> column_pressure;
      for (const auto &cell : tria.active_cell_iterators())
        {
          const Point<dim> c   = cell->center();
          const auto      &pts = points[cell->active_cell_index()];
          double           m = 0., pp = 0., gl = 0.;
          for (const auto &pt : pts)
            {
              m += pt.mu / pts.size();
              pp += pt.p / pts.size();
              gl += pt.g_loc / pts.size();
            }
          if (!column && !row)
            {
              auto &[sum, count] = column_pressure[static_cast<unsigned int>(
                  std::max(0., std::floor((c[along()] - scale.R_i) / scale.h)))];
              sum += pp / scale.P_wall;
              ++count;
              if (c[dim - 1] < scale.H - scale.h)
                continue; // the profile: the surface row
            }
          xc.push_back((c[along()] - (column ? 0. : scale.R_i)) / scale.d);
          mu.push_back(m);
          p.push_back(pp / scale.P_wall);
          gloc.push_back(gl / g_unit());
        }
      out.write_csv(
          "profiles/stress.csv",
          {profile_header[0], "mu", pressure_name(), "g_loc" + profile_header[2].substr(1)},
          {xc, mu, p, gloc});
      if (column || row)
        report_wall_pressure(summary, xc, p, finished);
      else
        {
          std::vector<double> x_column, p_column;
          for (const auto &[i, sum_count] : column_pressure)
            {
              x_column.push_back((i + 0.5) * scale.h / scale.d);
              p_column.push_back(sum_count.first / sum_count.second);
            }
          report_wall_pressure_with_gravity(summary, x_column, p_column, finished);
        }
    }

    template <int dim>
    void
    Problem<dim>::report_wall_pressure_with_gravity(nlohmann::json            &summary,
                                                    const std::vector<double> &xc,
                                                    const std::vector<double> &p_column,
                                                    const bool                 finished)
    {
      // With walls that carry no vertical shear stress, vertical equilibrium makes the mean of
      // -sigma_zz over a depth phi rho_s G (H - Z); where the stress is isotropic in the r-z plane,
      // as in the flowing band, so is p. Along the driven wall its mean is then the hydrostatic
      // phi rho_s G H / 2 that mu_wall divides the wall's shear stress by. Extrapolated linearly
      // from the two innermost columns of elements.
      const std::optional<double> extrapolated = extrapolate_to_wall(xc, p_column);
      if (!extrapolated || !summary["mu_wall"].is_number())
        return;
      const double p_wall                       = *extrapolated / 0.5; // over phi rho_s G H / 2
      const double mu_wall                      = summary["mu_wall"];
      summary["wall_pressure_over_hydrostatic"] = p_wall;
      summary["mu_wall_local"]                  = mu_wall / p_wall;
      if (finished && std::abs(p_wall - 1.) > 2e-3)
        {
          std::ostringstream w;
          w << "the mean pressure along the driven wall is " << p_wall
            << " times the hydrostatic phi rho_s G H / 2 that mu_wall is taken over: elastic "
               "stresses of the loading remain there (they relax under shearing: Loading/Wall "
               "rotation); mu_wall_local = "
            << mu_wall / p_wall << " divides by the wall's own mean pressure";
          report.warn(w.str());
        }
    }

    /// Near the rate-independent plateau mu_wall is mu_s plus a small rate-dependent part, which
    /// the comparison of mu_wall itself does not see (at P_wall / (phi rho_s G d) = 100, 1 % of
    /// mu_wall is more than mu_wall - mu_s). It is reported on its own, signed: for the column the
    /// wall's tau / P_wall; for the annulus row tau / p at the wall, as the FD solution of (92)
    /// has p = P_wall there and the FE's wall pressure still carries stresses of the loading. At
    /// h = d / 3 it is 11 to 82 % off at most of the paper's settings (docs/ngf.md); no warning,
    /// as the paper's own resolution is the case files'.
    template <int dim>
    void
    Problem<dim>::compare_rate_dependent_part(nlohmann::json &summary, const double mu_wall) const
    {
      const double mu_s = prm.material.nonlocal.mu_s;
      const double fd   = summary["reference"]["mu_wall"].get<double>() - mu_s;
      if (!(fd > 0.) || !std::isfinite(mu_wall))
        return;
      summary["reference"]["mu_wall_minus_mu_s"]      = fd;
      summary["reference"]["mu_wall_minus_mu_s_from"] = column ? "mu_wall" : "mu_wall_local";
      summary["reference"]["mu_wall_minus_mu_s_relative_difference"] = (mu_wall - mu_s) / fd - 1.;
    }

    template <int dim>
    void
    Problem<dim>::write_vtu(const Vector<double> &v)
    {
      DataOut<dim> data_out;
      data_out.attach_dof_handler(dof_handler);
      using DCI = DataComponentInterpretation::DataComponentInterpretation;
      std::vector<std::string> names, vnames;
      std::vector<DCI>         kinds;
      if (dim == 3)
        {
          names  = {"displacement", "displacement", "displacement", "g"};
          vnames = {"velocity", "velocity", "velocity", "dg_dt"};
          kinds  = {DataComponentInterpretation::component_is_part_of_vector,
                    DataComponentInterpretation::component_is_part_of_vector,
                    DataComponentInterpretation::component_is_part_of_vector,
                    DataComponentInterpretation::component_is_scalar};
        }
      else
        {
          names  = {"displacement", "displacement", "theta", "g"};
          vnames = {"velocity_rz", "velocity_rz", "v_theta", "dg_dt"};
          kinds  = {DataComponentInterpretation::component_is_part_of_vector,
                    DataComponentInterpretation::component_is_part_of_vector,
                    DataComponentInterpretation::component_is_scalar,
                    DataComponentInterpretation::component_is_scalar};
        }
      data_out.add_data_vector(U, names, DataOut<dim>::type_dof_data, kinds);
      data_out.add_data_vector(v, vnames, DataOut<dim>::type_dof_data, kinds);
      // The wall-parallel speed over v_wall (Fig. 6: v / (R_i Omega)), nodal, in component 0.
      Vector<double> speed(v.size());
      for (types::global_dof_index i = 0; i < v.size(); ++i)
        if (dof_component[i] == 0)
          speed[i] = wall_parallel_speed(i, v) / scale.v_wall;
      class FirstComponent : public DataPostprocessorScalar<dim>
      {
      public:
        FirstComponent()
            : DataPostprocessorScalar<dim>("v_over_v_wall", update_values)
        {
        }
        void
        evaluate_vector_field(const DataPostprocessorInputs::Vector<dim> &in,
                              std::vector<Vector<double>>                &computed) const override
        {
          for (unsigned int q = 0; q < in.solution_values.size(); ++q)
            computed[q](0) = in.solution_values[q][0];
        }
      } first_component;
      data_out.add_data_vector(speed, first_component);
      const unsigned int n = tria.n_active_cells();
      Vector<float>      mu(n), p(n), p_scaled(n), tau(n), gamma_dot(n);
      for (unsigned int c = 0; c < n; ++c)
        for (const auto &pt : points[c])
          {
            mu[c] += pt.mu / points[c].size();
            p[c] += pt.p / points[c].size();
            p_scaled[c] += pt.p / scale.P_wall / points[c].size();
            tau[c] += pt.tau / points[c].size();
            gamma_dot[c] += pt.gamma_dot_p / points[c].size();
          }
      data_out.add_data_vector(mu, "mu");
      data_out.add_data_vector(p, "pressure");
      data_out.add_data_vector(p_scaled, pressure_name());
      data_out.add_data_vector(tau, "equivalent_shear_stress");
      data_out.add_data_vector(gamma_dot, "plastic_shear_rate");
      data_out.build_patches();
      out.write_solution(data_out);
    }
  } // namespace

  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log)
  {
    if (parameters.geometry.shape == "shear column" || parameters.geometry.shape == "annulus slice")
      {
        Problem<3> problem(parameters, output, log);
        return problem.run();
      }
    Problem<2> problem(parameters, output, log);
    return problem.run();
  }
} // namespace granflow::ngf
