// Internal to the dp model, shared by its source files: the Problem of one run and its helpers.
// Daviet & Bertails-Descoubes 2016, Sections 4.1-4.5 and 6.1-6.3. The public interface is
// dp_model.h; the members are defined by topic: dp_setup.cc (mesh, boundary conditions, the checks
// of the input that need the mesh), dp_assemble.cc (the operators of (25) and the residual's
// scale), dp_model.cc (the solve and run()), dp_postprocess.cc (fields, profiles, forces, summary,
// VTU).
#pragma once

#include "models/dp/dp_model.h"

#include "core/errors.h"
#include "core/interrupt.h"
#include "core/parameters.h"
#include "core/run_report.h"
#include "fem/mapping_without_cell_similarity.h"
#include "geometry/geometry.h"
#include "postprocess/profiles.h"
#include "rheology/drucker_prager.h"
#include "solvers/cholmod_solver.h"
#include "solvers/cone_problem.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace granflow::dp::detail
{
  using namespace dealii;
  constexpr int          dim = 2;
  constexpr unsigned int s_d = rheology::n_sym<dim>; // 3 components per constraint point
  using SymVector            = rheology::SymVector<dim>;

  /// "No-slip, Zero x-velocity, ...": the velocity conditions' entries, for messages.
  inline std::string
  velocity_condition_entries(const BoundaryParameters &bc)
  {
    std::string list;
    for (const auto &condition : bc.velocity_conditions())
      list += (list.empty() ? "" : ", ") + std::string(condition.second);
    return list + ", Velocity";
  }

  /// Symmetric 3-point rule exact for degree 2 with positive weights (DESIGN.md): the
  /// constraint points of the P1d stress, so that R is square and invertible per element.
  inline Quadrature<dim>
  constraint_rule()
  {
    return Quadrature<dim>(
        {Point<dim>(1. / 6., 1. / 6.), Point<dim>(2. / 3., 1. / 6.), Point<dim>(1. / 6., 2. / 3.)},
        {1. / 6., 1. / 6., 1. / 6.});
  }

  /// Values at the vertices of the linear function taking the values v_q at the points of
  /// constraint_rule(): point q has barycentric weight 2/3 on vertex q, so V = (2 I - J/3) v.
  inline std::array<double, 3>
  vertex_values_from_points(const std::array<double, 3> &v)
  {
    const double sum = v[0] + v[1] + v[2];
    return {{2. * v[0] - sum / 3., 2. * v[1] - sum / 3., 2. * v[2] - sum / 3.}};
  }

  /// The CSR matrix of rows.size() x n_cols with the given rows (column -> value).
  inline solvers::CsrMatrix
  csr_from_rows(const std::vector<std::map<int, double>> &rows, const std::size_t n_cols)
  {
    solvers::CsrMatrix M;
    M.n_rows = rows.size();
    M.n_cols = n_cols;
    M.row_start.push_back(0);
    for (const auto &row : rows)
      {
        for (const auto &[j, a] : row)
          {
            M.column.push_back(j);
            M.value.push_back(a);
          }
        M.row_start.push_back(static_cast<int>(M.column.size()));
      }
    return M;
  }

  /// Calls visit(cell) for every cell face on boundary `id`, with `fvf` reinitialised on that
  /// face.
  template <typename Visit>
  void
  for_each_face_on(const DoFHandler<dim> &dofs, const types::boundary_id id, FEFaceValues<dim> &fvf,
                   const Visit &visit)
  {
    for (const auto &cell : dofs.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == id)
          {
            fvf.reinit(cell, f);
            visit(cell);
          }
  }

  class Problem
  {
  public:
    Problem(const Parameters &prm, OutputDirectory &out, Logger &log)
        : prm(prm)
        , out(out)
        , log(log)
        , mapping(FE_SimplexP<dim>(1))
        , fe_u(FE_SimplexP<dim>(2), dim)
        , p1d(prm.solver.stress_element == "P1d")
        , fe_s(p1d ? static_cast<const FiniteElement<dim> &>(fe_dgp1)
                   : static_cast<const FiniteElement<dim> &>(fe_p1))
    {
    }

    Results
    run();

  private:
    void
    make_mesh();
    /// The dofs, the boundary conditions, the unknowns of the cone problem; checks the inputs
    /// that need the mesh and notes what a user may not have meant.
    void
    setup();
    /// Velocity conditions, loads and the boundaries Output names, each checked against the
    /// mesh.
    void
    apply_boundary_conditions();
    void
    warn_of_tension();
    /// free_index, free_coefficient, reaction_dof and n_free from the constraints.
    void
    number_free_dofs();
    void
    note_unconditioned_and_unresolved_boundaries();
    std::string
    solver_failure(const solvers::ConeSolverStats &stats, bool interior_point) const;
    template <typename F>
    void
    for_each_boundary_node(const F &f) const;
    void
    constrain_directions();
    using CellList = std::vector<typename DoFHandler<dim>::active_cell_iterator>;
    /// The mesh's edge-connected pieces, each as its cells.
    std::vector<CellList>
    mesh_pieces() const;
    /// The mean of a piece's cell centres.
    static Point<dim>
    centre_of(const CellList &piece);
    /// "the part of the mesh around (x, y) (n of N triangles, ...)" for a piece of a mesh with
    /// several, "" for the whole mesh.
    std::string
    where_in_mesh(const CellList &piece) const;
    void
    require_no_free_rigid_motion(const std::vector<CellList> &pieces) const;
    void
    require_no_net_inflow_into_a_closed_domain(const std::vector<CellList> &pieces) const;
    void
    assemble_velocity_operator(const std::vector<double> &eta);
    void
    assemble_constraint_operator();
    void
    set_residual_scale(const std::vector<double> &eta);
    solvers::ConeSolverStats
    solve_cone_problem();
    /// The Bagnold loop's state after a solve.
    struct ViscosityChange
    {
      /// ||eta(u) - eta_used|| / ||eta(u)|| (L2 over the domain), eta(u) =
      /// bagnold_viscosity(D(u)) of the solve's velocity and eta_used the viscosity the solve
      /// was assembled with: the residual of the fixed point eta = |D(u(eta))|. (It compared
      /// eta(u) with eta(u_old) before, which is 0 wherever both strain rates are below the
      /// floor: a first solve whose strain rates were all below it passed as converged, with
      /// the starting eta = 1.) It is blind to rigid motions, which a moving boundary's u_D adds
      /// to u.
      double relative = 0.;
      /// The fraction of the domain's area where |D(u)| is below the viscosity floor.
      double floored_area_fraction = 0.;
      /// Daviet 6.1.3: eta(u) = |D(u)| = sqrt(D:D / 2) at the quadrature points of a(., .), cell
      /// by cell, bounded below by the viscosity floor (eta -> 0 at the free surface would make
      /// A singular): the loop's next viscosity comes from it.
      std::vector<double> eta_of_u;
    };
    /// eta_used per quadrature point of a(., .), cell by cell.
    ViscosityChange
    viscosity_change(const std::vector<double> &eta_used) const;
    /// Daviet 6.1.3: eta = |D(u)|, bounded below by the viscosity floor.
    double
    bagnold_viscosity(const SymmetricTensor<2, dim> &D) const
    {
      return std::max(rheology::tensor_norm(D), prm.rheology.viscosity_floor);
    }
    /// Values at the constraint points that postprocess() and its parts share.
    struct PointFields
    {
      std::vector<double> p, div_u, D0_norm;
      std::vector<double> zone; // 0 rigid, 1 flowing, 2 dilating
      double              max_D0 = 0., max_div = 0.;
      double              threshold = 0.; // the rigid threshold on the scaled strain rate
      std::size_t         n_rigid = 0, n_flowing = 0, n_dilating = 0;
      double              rigid_D0_min = std::numeric_limits<double>::infinity(), rigid_D0_max = 0.;
    };
    void
    postprocess(Results &results);
    PointFields
    point_fields();
    void
    warn_about_zones(const PointFields &pf);
    void
    write_velocity_profile(nlohmann::json &S, const PointFields &pf);
    /// The ends of the profile line: Output/Profile start and end, or, both empty, the vertical
    /// line through the middle of the mesh's bounding box.
    std::pair<Point<dim>, Point<dim>>
    profile_line() const;
    std::map<types::boundary_id, postprocess::BoundaryFlux>
    summarise_fluxes(nlohmann::json &S) const;
    /// Output/Inflow boundary's mean speed U_infinity (positive into the domain), its mean u_x,
    /// whether the channel is jammed (no direction, no dynamic pressure), and whether the
    /// material leaves through it instead (then Fr and C_D are null). All 0 / false without one.
    struct Inflow
    {
      double U_inf = 0., u_x = 0.;
      bool   jammed = false, reversed = false;
    };
    Inflow
    summarise_inflow(nlohmann::json                                                &S,
                     const std::map<types::boundary_id, postprocess::BoundaryFlux> &flux_of);
    /// The fraction of the constraint points of the cells on boundary `id` that are rigid.
    double
    rigid_fraction_next_to(types::boundary_id id, const std::vector<double> &zone) const;
    void
    summarise_drag(nlohmann::json &S, const PointFields &pf,
                   const std::map<types::boundary_id, postprocess::BoundaryFlux> &flux_of);
    /// The cylinder's wake and the upstream pressure peak, the flow running along `along` e_x.
    void
    summarise_cylinder_wake(nlohmann::json &S, const PointFields &pf, double along) const;
    void
    write_vtu();
    Tensor<1, dim>
    boundary_force(types::boundary_id id) const;
    Tensor<1, dim>
    viscous_traction_force(types::boundary_id id) const;

    const Parameters &prm;
    OutputDirectory  &out;
    Logger           &log;

    geometry::Mesh                        mesh;
    WithoutCellSimilarity<MappingFE, dim> mapping; // (fem/mapping_without_cell_similarity.h)
    FESystem<dim>                         fe_u;
    FE_SimplexP<dim>                      fe_p1{1};
    FE_SimplexDGP<dim>                    fe_dgp1{1};
    const bool                            p1d;
    const FiniteElement<dim>             &fe_s;
    DoFHandler<dim>                       dof_u, dof_s;
    QGaussSimplex<dim>                    quadrature{3};

    std::map<types::global_dof_index, double> dirichlet; // dof -> u_D
    /// A boundary with a velocity condition: the components it fixes (No-slip, Zero x- and
    /// y-velocity) or the direction of its faces along which the velocity is zero (Zero normal
    /// velocity: the normal; Zero tangential velocity: the tangent).
    struct VelocityBoundary
    {
      types::boundary_id id;
      ComponentMask      mask;
      enum class Direction
      {
        none,
        normal,
        tangent
      } direction = Direction::none;
      /// The direction along which the velocity is zero on a face with outward normal n (none
      /// for a component mask).
      static Tensor<1, dim>
      fixed_direction(const Direction kind, const Tensor<1, dim> &n)
      {
        return kind == Direction::normal ? n : Tensor<1, dim>({-n[1], n[0]});
      }
    };
    std::vector<VelocityBoundary> velocity_boundaries;
    /// Boundary conditions/External pressure, parsed once by setup(): (boundary, p_ext).
    std::vector<std::pair<types::boundary_id, double>> external_pressures;
    /// Boundary conditions/External stress, parsed once by setup(): (boundary, sigma_ext).
    std::vector<std::pair<types::boundary_id, SymmetricTensor<2, dim>>> external_stresses;
    /// Boundary conditions/Analytic traction, parsed once by setup().
    std::vector<types::boundary_id> analytic_tractions;
    /// The velocity dofs in terms of the unknowns w of the cone problem: u_i = c_i
    /// w_free_index[i] where free_index[i] >= 0, u_i = u_D otherwise. c_i = 1, except at a node
    /// with one constrained direction d (Zero normal or tangential velocity), whose two dofs
    /// share one unknown: u = w t with t perpendicular to d, c = (t_x, t_y).
    std::vector<int>    free_index;       // dof -> unknown or -1
    std::vector<double> free_coefficient; // c_i
    /// Dofs whose momentum equation is replaced by a velocity condition (prescribed dofs, and
    /// both dofs of a node with a constrained direction): their rows give the reactions.
    std::vector<bool> reaction_dof;
    /// Nodes with a constrained direction: x-dof -> (y-dof, unit d with u . d = 0).
    std::map<types::global_dof_index, std::pair<types::global_dof_index, Tensor<1, dim>>>
                            directed_nodes;
    std::size_t             n_free   = 0;
    std::size_t             n_points = 0;
    std::vector<double>     point_weight; // int alpha_i, or JxW of the point
    std::vector<Point<dim>> point_location;
    // Fields on the stress space (P1d or P1), one per quantity, for output and boundary integrals.
    std::map<std::string, Vector<double>> stress_fields;
    // The rows of the momentum equation at the constrained dofs, for the reaction forces:
    // A (all columns), l and H^T (columns of the constrained dofs), as assembled.
    std::map<types::global_dof_index, std::map<types::global_dof_index, double>> A_constrained;
    std::map<types::global_dof_index, std::map<std::size_t, double>>             H_constrained;
    std::vector<double>                                                          load_all;
    Vector<double> cell_zone; // 0 rigid, 1 flowing, 2 dilating

    solvers::ConeProblemData data;
    solvers::ConeSolution    solution;
    Vector<double>           u;                      // all velocity dofs
    std::vector<std::string> traction_free;          // named boundaries with no condition
    RunReport                report{log, out, "dp"}; // after log and out, which it refers to
    /// The ends of the profile line, set by setup(); none where the default line misses the mesh.
    std::optional<std::pair<Point<dim>, Point<dim>>> profile;
    nlohmann::json                                   solver_json;
    std::optional<interrupt::BeforeResults>          before_results; // see run()
  };

  /// Calls f(b, n, x, y, w) for every node of every boundary face: the face's boundary id b and
  /// outward unit normal n (faces are straight), the node's x- and y-dofs, and the integral w of
  /// its shape function over the face. (FiniteElement::has_support_on_face() is true for every
  /// dof of FE_SimplexP in 9.4, and the shape functions of other nodes are only about 1e-17 on
  /// the face, not 0: a face's nodes are its own dofs.)
  template <typename F>
  void
  Problem::for_each_boundary_node(const F &f) const
  {
    const QGauss<dim - 1>                face_quadrature(3);
    FEFaceValues<dim>                    fvf(mapping, fe_u, face_quadrature,
                                             update_values | update_normal_vectors | update_JxW_values);
    std::vector<types::global_dof_index> dofs(fe_u.n_dofs_per_cell()),
        face_dofs(fe_u.n_dofs_per_face());
    for (const auto &cell : dof_u.active_cell_iterators())
      for (const unsigned int face : cell->face_indices())
        {
          if (!cell->face(face)->at_boundary())
            continue;
          fvf.reinit(cell, face);
          cell->get_dof_indices(dofs);
          cell->face(face)->get_dof_indices(face_dofs);
          for (unsigned int k = 0; k < fe_u.n_dofs_per_cell(); ++k)
            {
              const auto [component, index] = fe_u.system_to_component_index(k);
              if (component != 0 ||
                  std::find(face_dofs.begin(), face_dofs.end(), dofs[k]) == face_dofs.end())
                continue;
              double w = 0.;
              for (unsigned int q = 0; q < face_quadrature.size(); ++q)
                w += fvf.shape_value(k, q) * fvf.JxW(q);
              f(cell->face(face)->boundary_id(), fvf.normal_vector(0), dofs[k],
                dofs[fe_u.component_to_system_index(1, index)], w);
            }
        }
  }

} // namespace granflow::dp::detail
