// Internal to the ngf model, shared by its source files: the Problem of one run and its helpers.
// Henann & Kamrin 2016, Sections 2-6. The public interface is ngf_model.h; the members are defined
// by topic: ngf_setup.cc (mesh, dofs, constraints), ngf_assemble.cc (residual, Jacobian, Newton),
// ngf_model.cc (the increments, steadiness, warnings, run()), ngf_postprocess.cc (profiles, W,
// the reference, the wall pressure, histories, VTU).
//
// Problem is a class template (dim = 2: the generalized-axisymmetric quads, 3: the bricks) whose
// members are defined in four files. Each file explicitly instantiates the members it defines, one
// by one: an explicit instantiation of the whole class may appear only once in a program, and would
// instantiate only the members defined in its own file.
#pragma once

#include "models/ngf/ngf_model.h"

#include "core/interrupt.h"
#include "core/run_report.h"
#include "models/ngf/ngf_element.h"
#include "postprocess/nonlocal_1d.h"
#include "solvers/newton.h"
#include "solvers/umfpack_solver.h"

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace granflow::ngf::detail
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

  /// The remedy the local model's warnings give. In the rate-independent regime its flow
  /// collapses into the first element at every resolution (Henann & Kamrin 2016, Fig. 7b; mu(I)
  /// is ill posed at low I, Barker et al. 2015): the column at v_wall = 1e-3 refined from h = d /
  /// 3 to d / 90 kept its band in one element (W = 0.63 h), mu_wall 0.391, 0.382, 0.372, 0.388.
  /// (W/d 0.211, 0.070, 0.051 at d / 3, d / 9, d / 27: the band's element count is no test, it
  /// reaches 1.4 at d / 27.) At higher rates refining does resolve it (v_wall = 0.1: 1.5
  /// elements at d / 3, 4.4 at d / 9, W/d 0.511 and 0.494, mu_wall the same to 3e-5).
  inline constexpr const char *local_localises =
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
    /// One increment's Newton iterations (solvers::NewtonSolver), logged to newton.csv.
    solvers::NewtonStats
    newton(double dt, unsigned int increment);

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
    /// The warning for a stress ratio tau / p at the driven wall (the summary's mu_wall_local,
    /// set by postprocess()) below mu_s, unless the fluidity conditions feed fluidity in.
    void
    warn_if_below_mu_s(const nlohmann::json &summary, bool steady_flow);
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
    double boundary_fluidity_supply = 0.;
    // The last factorised Jacobian, copied into CSR with sorted columns (UMFPACK's order) through
    // csr_position, and factorised without UMFPACK's iterative refinement (setup_system()); the
    // symbolic analysis, of the first Jacobian, is kept for the run.
    solvers::CsrMatrix        jacobian_csr;
    std::vector<unsigned int> csr_position; // of each entry of `jacobian`, in its storage order
    solvers::UmfpackSolver    factorization;
    solvers::NewtonSolver<Vector<double>>         newton_solver;
    /// Until the loading increment converges, a signal ends the run at once and leaves the
    /// output directory as it was: there is nothing to write (run(), march()).
    std::optional<interrupt::BeforeResults>       before_results;
    std::vector<Point<dim>>                       dof_point; // reference position of each dof
    std::optional<postprocess::Nonlocal1dProfile> reference; // Output/Reference
  };
} // namespace granflow::ngf::detail
