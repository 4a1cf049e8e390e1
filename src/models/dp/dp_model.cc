// Daviet & Bertails-Descoubes 2016, Sections 4.1-4.5 and 6.1-6.3; see dp_model.h.
#include "models/dp/dp_model.h"

#include "core/errors.h"
#include "core/interrupt.h"
#include "core/parameters.h"
#include "core/run_report.h"
#include "fem/mapping_without_cell_similarity.h"
#include "geometry/geometry.h"
#include "postprocess/analytic.h"
#include "postprocess/profiles.h"
#include "rheology/drucker_prager.h"
#include "solvers/cholmod_solver.h"
#include "solvers/cone_problem.h"

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

namespace granflow::dp
{
  namespace
  {
    using namespace dealii;
    constexpr int          dim = 2;
    constexpr unsigned int s_d = rheology::n_sym<dim>; // 3 components per constraint point
    using SymVector            = rheology::SymVector<dim>;

    /// "No-slip, Zero x-velocity, ...": the velocity conditions' entries, for messages.
    std::string
    velocity_condition_entries(const BoundaryParameters &bc)
    {
      std::string list;
      for (const auto &condition : bc.velocity_conditions())
        list += (list.empty() ? "" : ", ") + std::string(condition.second);
      return list + ", Velocity";
    }

    /// Symmetric 3-point rule exact for degree 2 with positive weights (DESIGN.md): the
    /// constraint points of the P1d stress, so that R is square and invertible per element.
    Quadrature<dim>
    constraint_rule()
    {
      return Quadrature<dim>({Point<dim>(1. / 6., 1. / 6.), Point<dim>(2. / 3., 1. / 6.),
                              Point<dim>(1. / 6., 2. / 3.)},
                             {1. / 6., 1. / 6., 1. / 6.});
    }

    /// Values at the vertices of the linear function taking the values v_q at the points of
    /// constraint_rule(): point q has barycentric weight 2/3 on vertex q, so V = (2 I - J/3) v.
    std::array<double, 3>
    vertex_values_from_points(const std::array<double, 3> &v)
    {
      const double sum = v[0] + v[1] + v[2];
      return {{2. * v[0] - sum / 3., 2. * v[1] - sum / 3., 2. * v[2] - sum / 3.}};
    }

    /// Calls visit(cell) for every cell face on boundary `id`, with `fvf` reinitialised on that
    /// face.
    template <typename Visit>
    void
    for_each_face_on(const DoFHandler<dim> &dofs, const types::boundary_id id,
                     FEFaceValues<dim> &fvf, const Visit &visit)
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
        , fe_s(p1d ? static_cast<const FiniteElement<dim> &>(fe_dgp1) :
                     static_cast<const FiniteElement<dim> &>(fe_p1))
      {}

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
      /// free_index, free_coefficient, reaction_dof and n_free from the constraints.
      void
      warn_of_tension();
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
      std::vector<double>
      viscosity_from_velocity() const;
      /// ||eta(u) - eta(u_old)|| / ||eta(u)|| (L2 over the domain) with eta = bagnold_viscosity(D):
      /// the Bagnold loop's change. It is blind to rigid motions, which a moving boundary's u_D
      /// adds to u, and to strain rates below the viscosity floor (a rigid zone's solver noise),
      /// which do not change eta.
      double
      viscosity_change(const Vector<double> &u_old) const;
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
        double rigid_D0_min = std::numeric_limits<double>::infinity(), rigid_D0_max = 0.;
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

      geometry::Mesh     mesh;
      WithoutCellSimilarity<MappingFE, dim> mapping; // (fem/mapping_without_cell_similarity.h)
      FESystem<dim>      fe_u;
      FE_SimplexP<dim>   fe_p1{1};
      FE_SimplexDGP<dim> fe_dgp1{1};
      const bool         p1d;
      const FiniteElement<dim> &fe_s;
      DoFHandler<dim>    dof_u, dof_s;
      QGaussSimplex<dim> quadrature{3};

      std::map<types::global_dof_index, double> dirichlet;  // dof -> u_D
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
      std::size_t                               n_free = 0;
      std::size_t                               n_points = 0;
      std::vector<double>                       point_weight; // int alpha_i, or JxW of the point
      std::vector<Point<dim>>                   point_location;
      // Fields on the stress space (P1d or P1), one per quantity, for output and boundary integrals.
      std::map<std::string, Vector<double>>     stress_fields;
      // The rows of the momentum equation at the constrained dofs, for the reaction forces:
      // A (all columns), l and H^T (columns of the constrained dofs), as assembled.
      std::map<types::global_dof_index, std::map<types::global_dof_index, double>> A_constrained;
      std::map<types::global_dof_index, std::map<std::size_t, double>>             H_constrained;
      std::vector<double>                                                          load_all;
      Vector<double>                            cell_zone; // 0 rigid, 1 flowing, 2 dilating

      solvers::ConeProblemData data;
      solvers::ConeSolution    solution;
      Vector<double>           u;             // all velocity dofs
      std::vector<std::string> traction_free; // named boundaries with no condition
      RunReport                report{log, out, "dp"}; // after log and out, which it refers to
      /// The ends of the profile line, set by setup(); none where the default line misses the mesh.
      std::optional<std::pair<Point<dim>, Point<dim>>> profile;
      nlohmann::json           solver_json;
      std::optional<interrupt::BeforeResults> before_results; // see run()
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

    /// Zero normal and Zero tangential velocity: at each node of these faces, u . d = 0 along
    /// one direction d: the faces' normal (free slip) or tangent (flow normal to the boundary).
    /// Where faces meet at an angle, d is sum_f w_f d_f normalised, w_f the integral of the
    /// node's shape function on face f (each d_f turned to agree in sign with the first): for a
    /// slip wall, Engelman's consistent normal, with which the flux through the wall is zero in
    /// all (each face's is not, at a kink). That lets the flow follow a polygonal wall, or the
    /// chords of a curved one, round its kinks. Where two faces' directions differ by more than 45
    /// degrees, as at the corner of a box, no direction is free and the node is fixed (u = 0); so
    /// is a node where another velocity condition already fixes a component other than along d.
    void
    Problem::constrain_directions()
    {
      const auto &bc  = prm.boundaries;
      using Direction = VelocityBoundary::Direction;
      std::map<types::boundary_id, Direction> direction_of;
      for (const auto &[list, direction, entry] :
           {std::make_tuple(&bc.zero_normal_velocity, Direction::normal,
                            "Boundary conditions/Zero normal velocity"),
            std::make_tuple(&bc.zero_tangential_velocity, Direction::tangent,
                            "Boundary conditions/Zero tangential velocity")})
        for (const std::string &name : split_list(*list))
          {
            const types::boundary_id id = mesh.id(name, prm.case_file, entry);
            direction_of[id]            = direction;
            velocity_boundaries.push_back({id, ComponentMask(dim, false), direction});
          }
      if (direction_of.empty())
        return;

      struct Node
      {
        types::global_dof_index     y;
        Tensor<1, dim>              sum;  // sum_f w_f d_f, signs aligned
        std::vector<Tensor<1, dim>> n;    // the outward normal of each face
        std::vector<Direction>      kind; // and its condition
      };
      std::map<types::global_dof_index, Node> nodes; // by x-dof
      for_each_boundary_node([&](const types::boundary_id b, const Tensor<1, dim> &n,
                                 const types::global_dof_index x, const types::global_dof_index y,
                                 const double w) {
        const auto direction = direction_of.find(b);
        if (direction == direction_of.end())
          return;
        const Tensor<1, dim> d    = VelocityBoundary::fixed_direction(direction->second, n);
        Node                &node = nodes[x];
        node.y                    = y;
        const bool agrees =
            node.n.empty() || VelocityBoundary::fixed_direction(node.kind[0], node.n[0]) * d >= 0.;
        node.sum += (agrees ? w : -w) * d;
        node.n.push_back(n);
        node.kind.push_back(direction->second);
      });

      const double cos_corner = std::cos(numbers::PI / 4.), cos_same = std::cos(numbers::PI / 180.);
      for (const auto &[x, node] : nodes)
        {
          const bool fixed_x = dirichlet.count(x), fixed_y = dirichlet.count(node.y);
          if (fixed_x && fixed_y)
            continue; // No-slip
          // Faces with the same condition may meet at a kink of up to 45 degrees (their outward
          // normals within 45 degrees, signs included: the two walls of a narrow V are a
          // corner). Faces with different conditions share a node only if they fix the same
          // direction (a slip floor and the end of a channel normal to it), to 1 degree.
          const auto d_of = [&](const std::size_t f) {
            return VelocityBoundary::fixed_direction(node.kind[f], node.n[f]);
          };
          bool corner = false;
          for (std::size_t a = 0; a < node.n.size(); ++a)
            for (std::size_t b = 0; b < a; ++b)
              corner =
                  corner || (node.kind[a] == node.kind[b] ? node.n[a] * node.n[b] < cos_corner
                                                          : std::abs(d_of(a) * d_of(b)) < cos_same);
          Tensor<1, dim> d = node.sum / node.sum.norm();
          for (unsigned int c = 0; c < dim; ++c) // an axis stays an axis, to the last bit
            if (std::abs(d[c]) < 1e-14)
              d[c] = 0.;
          d /= d.norm();
          // A component already fixed (Zero x- or y-velocity) leaves nothing free unless d is
          // that component's axis, when u . d = 0 holds already.
          if (fixed_x || fixed_y)
            corner = corner || std::abs(d[fixed_x ? 1 : 0]) > 1e-12;
          if (corner)
            {
              dirichlet.emplace(x, 0.);
              dirichlet.emplace(node.y, 0.);
            }
          else if (!fixed_x && !fixed_y)
            directed_nodes[x] = {node.y, d};
        }
    }

    /// The mesh's edge-connected pieces (a user mesh may have several), each as its cells.
    std::vector<Problem::CellList>
    Problem::mesh_pieces() const
    {
      std::vector<CellList> pieces;
      std::vector<bool>     seen_cell(mesh.triangulation.n_active_cells(), false);
      for (const auto &seed : dof_u.active_cell_iterators())
        {
          if (seen_cell[seed->active_cell_index()])
            continue;
          CellList stack{seed}, cells;
          seen_cell[seed->active_cell_index()] = true;
          while (!stack.empty())
            {
              const auto cell = stack.back();
              stack.pop_back();
              cells.push_back(cell);
              for (const unsigned int f : cell->face_indices())
                if (!cell->at_boundary(f) && !seen_cell[cell->neighbor(f)->active_cell_index()])
                  {
                    seen_cell[cell->neighbor(f)->active_cell_index()] = true;
                    stack.push_back(cell->neighbor(f));
                  }
            }
          pieces.push_back(std::move(cells));
        }
      return pieces;
    }

    Point<dim>
    Problem::centre_of(const CellList &piece)
    {
      Point<dim> centre;
      for (const auto &cell : piece)
        centre += cell->center() / static_cast<double>(piece.size());
      return centre;
    }

    std::string
    Problem::where_in_mesh(const CellList &piece) const
    {
      if (piece.size() == mesh.triangulation.n_active_cells())
        return "";
      const Point<dim>   centre = centre_of(piece);
      std::ostringstream where;
      where << "the part of the mesh around (" << centre[0] << ", " << centre[1] << ") ("
            << piece.size() << " of " << mesh.triangulation.n_active_cells()
            << " triangles, joined to the rest by no edge)";
      return where.str();
    }

    /// A (25a) vanishes on rigid motions (D(u) = 0), so the velocity conditions must leave none
    /// free on any piece of the mesh; else A is singular, and a Cholesky factorisation in floating
    /// point need not notice (tiny positive pivots): the velocity would come out as 1e14 with a
    /// "converged" residual. On each edge-connected piece, the rigid motions u = (a - w y, b + w x)
    /// that vanish at the constrained dofs are the kernel of the rows (1, 0, -y) for an x-dof and
    /// (0, 1, x) for a y-dof (coordinates centred and scaled on the piece): their Gram matrix must
    /// be regular.
    void
    Problem::require_no_free_rigid_motion(const std::vector<CellList> &pieces) const
    {
      std::map<types::global_dof_index, Point<dim>> support;
      DoFTools::map_dofs_to_support_points(mapping, dof_u, support);
      std::vector<types::global_dof_index> dofs(fe_u.n_dofs_per_cell());
      for (const CellList &cells : pieces)
        {
          const Point<dim> centre = centre_of(cells);
          double           size   = 0.;
          for (const auto &cell : cells)
            for (const unsigned int v : cell->vertex_indices())
              size = std::max(size, cell->vertex(v).distance(centre));
          SymmetricTensor<2, 3>             gram;
          std::set<types::global_dof_index> seen;
          for (const auto &cell : cells)
            {
              cell->get_dof_indices(dofs);
              for (unsigned int i = 0; i < dofs.size(); ++i)
                {
                  const auto directed = directed_nodes.find(dofs[i]);
                  if ((!dirichlet.count(dofs[i]) && directed == directed_nodes.end()) ||
                      !seen.insert(dofs[i]).second)
                    continue;
                  // The velocity along e (a component, or the constrained direction d) is zero.
                  Tensor<1, dim> e;
                  if (directed != directed_nodes.end())
                    e = directed->second.second;
                  else
                    e[fe_u.system_to_component_index(i).first] = 1.;
                  const Tensor<1, dim> x = (support.at(dofs[i]) - centre) / size;
                  const Tensor<1, 3>   row({e[0], e[1], e[1] * x[0] - e[0] * x[1]});
                  gram += symmetrize(outer_product(row, row));
                }
            }
          const auto modes = eigenvectors(gram); // descending: modes.back() is the least fixed
          if (modes.back().first > 1e-10 * std::max(trace(gram), 1.))
            continue;
          Tensor<1, 3> m = modes.back().second;
          if (std::abs(m[0]) >= std::abs(m[1]) ? m[0] < 0. : m[1] < 0.)
            m *= -1.;
          std::ostringstream what;
          if (trace(gram) == 0.)
            what << "no velocity condition applies";
          else if (std::abs(m[2]) > std::hypot(m[0], m[1]))
            what << "the velocity can still rotate";
          else
            {
              // rounding's 1e-17 printed as 0
              const auto component = [&](const double c) {
                const double x = c / std::hypot(m[0], m[1]);
                return std::abs(x) < 1e-9 ? 0. : x;
              };
              what << std::setprecision(3) << "the velocity can still translate along ("
                   << component(m[0]) << ", " << component(m[1]) << ")";
            }
          const std::string where = where_in_mesh(cells);
          // Named as the whole subsection: any of its velocity conditions can fix the motion.
          throw InputError(prm.case_file, "Boundary conditions",
                           "with its velocity conditions (" +
                               velocity_condition_entries(prm.boundaries) + ") " + what.str() +
                               (where.empty() ? "" : " on " + where) +
                               " (A is singular): expected velocity conditions that fix both "
                               "translations and the rotation of every part of the mesh");
        }
    }

    /// In a domain whose every boundary face has its normal velocity prescribed, int div u =
    /// int u_D . n: where Boundary conditions/Velocity pushes more material in than it lets out,
    /// no velocity has div u >= 0 (24) and the cone problem has no solution; the solvers would
    /// only say that they did not converge. The flux is that of the interpolated u_D, the one
    /// the discrete problem sees. Each piece of the mesh is a domain of its own.
    void
    Problem::require_no_net_inflow_into_a_closed_domain(const std::vector<CellList> &pieces) const
    {
      if (prm.boundaries.velocity.empty())
        return;
      const QGauss<dim - 1>            face_quadrature(3); // u_D is P2 on straight faces
      FEFaceValues<dim>                fvf(mapping, fe_u, face_quadrature,
                                           update_values | update_normal_vectors | update_JxW_values);
      const FEValuesExtractors::Vector velocity(0);
      Vector<double>                   u_D(dof_u.n_dofs());
      for (const auto &[i, value] : dirichlet)
        u_D[i] = value;
      std::vector<Tensor<1, dim>> values(face_quadrature.size());
      // The net and the gross flux into a piece, or nothing if a face of it is open.
      const auto closed_flux =
          [&](const CellList &piece) -> std::optional<std::pair<double, double>> {
        double net = 0., gross = 0.;
        for (const auto &cell : piece)
          for (const unsigned int f : cell->face_indices())
            if (cell->face(f)->at_boundary())
              {
                fvf.reinit(cell, f);
                const Tensor<1, dim> n = fvf.normal_vector(0);
                // closed: both components fixed (No-slip, Velocity), the normal one (free slip),
                // or the one component fixed (Zero x- or y-velocity) is the normal's
                bool closed = false;
                for (const auto &vb : velocity_boundaries)
                  if (vb.id == cell->face(f)->boundary_id())
                    {
                      if (vb.direction == VelocityBoundary::Direction::normal ||
                          (vb.direction == VelocityBoundary::Direction::none &&
                           vb.mask.n_selected_components(dim) == dim))
                        closed = true;
                      else if (vb.direction == VelocityBoundary::Direction::none)
                        for (unsigned int c = 0; c < dim; ++c)
                          closed = closed || (vb.mask[c] && std::abs(n[c]) > 1. - 1e-12);
                    }
                if (!closed)
                  return std::nullopt; // material can leave (or enter) through this face
                fvf[velocity].get_function_values(u_D, values);
                double flux = 0.;
                for (unsigned int q = 0; q < face_quadrature.size(); ++q)
                  flux += values[q] * fvf.normal_vector(q) * fvf.JxW(q);
                net += flux;
                gross += std::abs(flux);
              }
        return std::make_pair(net, gross);
      };
      for (const CellList &piece : pieces)
        if (const auto flux = closed_flux(piece); flux && flux->first < -1e-9 * flux->second)
          {
            const std::string  where = where_in_mesh(piece);
            std::ostringstream what;
            what << std::setprecision(3) << "pushes a net volume flux of " << -flux->first
                 << " into " << (where.empty() ? "a domain" : where)
                 << " that the velocity conditions close on every side; the material "
                    "cannot be compressed (div u >= 0, Daviet (24)): expected velocities whose "
                    "outflow is at least their inflow, or a boundary left open (one with no "
                    "velocity "
                    "condition, External pressure or External stress)";
            throw InputError(prm.case_file, "Boundary conditions/Velocity", what.str());
          }
    }

    /// Daviet (25a): a(u, v) = 2/Re int eta (D0(u):D0(v) + b/d div u div v), l(v) = int e_g . v
    /// + int_{B_N} sigma_ext n . v. A is kept on the free dofs; the Dirichlet lifting moves to l.
    void
    Problem::assemble_velocity_operator(const std::vector<double> &eta)
    {
      const auto t0 = std::chrono::steady_clock::now();
      const double  Re = prm.rheology.Re, b = prm.rheology.b;
      const Tensor<1, dim> e_g = prm.e_g();
      FEValues<dim> fv(mapping, fe_u, quadrature,
                       update_values | update_gradients | update_JxW_values | update_quadrature_points);
      const FEValuesExtractors::Vector velocity(0);
      const unsigned int n = fe_u.n_dofs_per_cell(), nq = quadrature.size();
      std::vector<types::global_dof_index> dofs(n);
      std::vector<std::map<int, double>>   rows(n_free);
      std::vector<double>                  load(dof_u.n_dofs(), 0.), lifting(n_free, 0.);
      std::vector<SymmetricTensor<2, dim>> eps(n);
      A_constrained.clear();
      std::vector<double>                  div(n);
      std::size_t                          cell_index = 0;
      for (const auto &cell : dof_u.active_cell_iterators())
        {
          fv.reinit(cell);
          cell->get_dof_indices(dofs);
          for (unsigned int q = 0; q < nq; ++q, ++cell_index)
            {
              const double w = 2. / Re * eta[cell_index] * fv.JxW(q);
              for (unsigned int i = 0; i < n; ++i)
                {
                  eps[i] = deviator(fv[velocity].symmetric_gradient(i, q));
                  div[i] = fv[velocity].divergence(i, q);
                  load[dofs[i]] += e_g * fv[velocity].value(i, q) * fv.JxW(q);
                }
              for (unsigned int i = 0; i < n; ++i)
                {
                  if (reaction_dof[dofs[i]])
                    {
                      auto &row = A_constrained[dofs[i]];
                      for (unsigned int j = 0; j < n; ++j)
                        row[dofs[j]] += w * (eps[i] * eps[j] + b / dim * div[i] * div[j]);
                    }
                  // A_w = C^T A C and l_w = C^T (l - A u_D), C the map u = C w + u_D.
                  const int    I  = free_index[dofs[i]];
                  const double ci = I >= 0 ? free_coefficient[dofs[i]] : 0.;
                  if (ci == 0.)
                    continue;
                  auto &row = rows[I];
                  for (unsigned int j = 0; j < n; ++j)
                    {
                      const double a = w * (eps[i] * eps[j] + b / dim * div[i] * div[j]);
                      if (const int J = free_index[dofs[j]]; J >= 0)
                        {
                          if (free_coefficient[dofs[j]] != 0.)
                            row[J] += ci * free_coefficient[dofs[j]] * a;
                        }
                      else
                        lifting[I] -= ci * a * dirichlet.at(dofs[j]);
                    }
                }
            }
        }

      // l += int_{boundary} t(x, n) . v for a traction t on the named boundary.
      const auto add_traction = [&](const types::boundary_id id, const unsigned int n_q,
                                    const auto &t) {
        const QGauss<dim - 1> face_quadrature(n_q);
        FEFaceValues<dim>     fvf(mapping, fe_u, face_quadrature,
                                  update_values | update_normal_vectors | update_JxW_values |
                                      update_quadrature_points);
        for_each_face_on(dof_u, id, fvf, [&](const auto &cell) {
          cell->get_dof_indices(dofs);
          for (unsigned int q = 0; q < face_quadrature.size(); ++q)
            {
              const Tensor<1, dim> traction = t(fvf.quadrature_point(q), fvf.normal_vector(q));
              for (unsigned int i = 0; i < n; ++i)
                load[dofs[i]] += traction * fvf[velocity].value(i, q) * fvf.JxW(q);
            }
        });
      };

      // Neumann boundaries (21): traction sigma_ext n, with sigma_ext = -p_ext I (External
      // pressure) or as given (External stress).
      for (const auto &[id, p_ext] : external_pressures)
        add_traction(id, 3, [p_ext = p_ext](const Point<dim> &, const Tensor<1, dim> &normal) {
          return -p_ext * normal;
        });

      for (const auto &[id, sigma_ext] : external_stresses)
        add_traction(id, 3,
                     [sigma_ext = sigma_ext](const Point<dim> &, const Tensor<1, dim> &normal) {
                       return sigma_ext * normal;
                     });

      // Boundaries loaded by the traction of the analytic reference: Bagnold (6.1.3), the
      // upstream / downstream stresses of the infinite layer. In the frame of the plane,
      // sigma_tot = [[-p, s], [s, -p]] with p = (1 - y) cos a and s = (1 - y) sin a (the viscous
      // part eta u' = (sin a - mu cos a)(1 - y) plus the saturated friction mu p).
      const double alpha = std::atan2(e_g[0], -e_g[1]);
      for (const types::boundary_id id : analytic_tractions)
        add_traction(id, 4, [alpha](const Point<dim> &x, const Tensor<1, dim> &normal) {
          Tensor<2, dim> sigma;
          sigma[0][0] = sigma[1][1] = -(1. - x[1]) * std::cos(alpha);
          sigma[0][1] = sigma[1][0] = (1. - x[1]) * std::sin(alpha);
          return sigma * normal;
        });

      // The solvers' sparse matrices have 32-bit indices (CHOLMOD, UMFPACK 'di'). The largest is
      // the interior point's augmented matrix: A, H^T, and per point n rows over the union of its
      // rows' columns plus an n x n block, at most nnz(A) + (n + 1) nnz(H) + n^2 points.
      std::size_t nnz_A = 0;
      for (const auto &row : rows)
        nnz_A += row.size();
      const std::size_t s_d = data.block_size;
      if (nnz_A + (s_d + 1) * data.H.column.size() + s_d * s_d * data.n_points() >
          static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw InputError(prm.case_file, "Geometry/Mesh size",
                         "the mesh (" + std::to_string(data.n_points()) +
                             " constraint points) is too large for the solvers' 32-bit sparse "
                             "indices: expected a coarser mesh");
      data.A        = solvers::CsrMatrix();
      data.A.n_rows = data.A.n_cols = n_free;
      data.A.row_start.push_back(0);
      for (const auto &row : rows)
        {
          for (const auto &[j, a] : row)
            {
              data.A.column.push_back(j);
              data.A.value.push_back(a);
            }
          data.A.row_start.push_back(static_cast<int>(data.A.column.size()));
        }
      data.l = std::move(lifting);
      for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
        if (free_index[i] >= 0)
          data.l[free_index[i]] += free_coefficient[i] * load[i];
      load_all              = std::move(load); // body force and tractions, no lifting
      report.timings["assemble_A"] =
          report.timings.value("assemble_A", 0.) +
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }

    /// Daviet (34b)/(35b): gamma = H u + k with H = R^{+T} B. With P1d stress and constraints at
    /// the quadrature points, R is invertible per element and gamma_q = JxW_q 2 chi^{-1}(D(u)(x_q));
    /// with continuous P1 stress at the nodes, gamma_i = int alpha_i 2 chi^{-1}(D(u)) (B exact,
    /// m by the trapezoidal rule). Either way H^T lambda = int D(v) : lambda_h (Property 1).
    void
    Problem::assemble_constraint_operator()
    {
      const FEValuesExtractors::Vector velocity(0);
      const Quadrature<dim> rule = p1d ? constraint_rule() : Quadrature<dim>(quadrature);
      FEValues<dim>         fv(mapping, fe_u, rule,
                       update_gradients | update_JxW_values | update_quadrature_points);
      FEValues<dim>         fv_s(mapping, fe_s, rule, update_values);
      const unsigned int    n = fe_u.n_dofs_per_cell(), ns = fe_s.n_dofs_per_cell();
      std::vector<types::global_dof_index> dofs(n), sdofs(ns);
      std::vector<std::map<int, double>>   rows(n_points * s_d);
      data.k.assign(n_points * s_d, 0.);
      point_weight.assign(n_points, 0.);
      point_location.assign(n_points, Point<dim>());
      if (!p1d)
        DoFTools::map_dofs_to_support_points(mapping, dof_s, point_location);

      auto add_point = [&](const std::size_t point, const double weight, const unsigned int q) {
        point_weight[point] += weight;
        for (unsigned int i = 0; i < n; ++i)
          {
            const SymVector g = rheology::chi_inverse<dim>(fv[velocity].symmetric_gradient(i, q));
            for (unsigned int c = 0; c < s_d; ++c)
              {
                const double h = 2. * weight * g[c];
                if (h == 0.)
                  continue;
                if (free_index[dofs[i]] < 0)
                  data.k[point * s_d + c] += h * dirichlet.at(dofs[i]);
                else if (free_coefficient[dofs[i]] != 0.)
                  rows[point * s_d + c][free_index[dofs[i]]] += free_coefficient[dofs[i]] * h;
                if (reaction_dof[dofs[i]])
                  H_constrained[dofs[i]][point * s_d + c] += h;
              }
          }
      };

      auto cell_s = dof_s.begin_active();
      for (const auto &cell : dof_u.active_cell_iterators())
        {
          fv.reinit(cell);
          cell->get_dof_indices(dofs);
          if (p1d)
            for (unsigned int q = 0; q < rule.size(); ++q)
              {
                const std::size_t point = cell->active_cell_index() * rule.size() + q;
                point_location[point]   = fv.quadrature_point(q);
                add_point(point, fv.JxW(q), q);
              }
          else
            {
              fv_s.reinit(cell_s);
              cell_s->get_dof_indices(sdofs);
              for (unsigned int q = 0; q < rule.size(); ++q)
                for (unsigned int a = 0; a < ns; ++a)
                  add_point(sdofs[a], fv_s.shape_value(a, q) * fv.JxW(q), q);
            }
          ++cell_s;
        }

      data.H        = solvers::CsrMatrix();
      data.H.n_rows = n_points * s_d;
      data.H.n_cols = n_free;
      data.H.row_start.push_back(0);
      for (const auto &row : rows)
        {
          for (const auto &[j, h] : row)
            {
              data.H.column.push_back(j);
              data.H.value.push_back(h);
            }
          data.H.row_start.push_back(static_cast<int>(data.H.column.size()));
        }
      data.block_size = s_d;
      data.mu.assign(n_points, prm.rheology.mu);
      data.Bi.assign(n_points, prm.rheology.Bi);
    }

    /// The residual compares lambda_i (a stress, in units of rho g L) with eta_i gamma_i /
    /// (Re w_i): gamma_i / (2 w_i) is the strain rate at the point, and 2 eta / Re times it the
    /// viscous stress it drives (23). An absolute tolerance then means the same on any mesh
    /// (gamma_i alone shrinks with the point's weight: small elements were barely constrained)
    /// and at any Re (the velocity of a flow scales with Re: slow flows passed at the start).
    /// eta_i is the mean of eta over the point's triangle (P1d) or the triangles at its node (P1).
    void
    Problem::set_residual_scale(const std::vector<double> &eta)
    {
      const unsigned int                   nq = quadrature.size();
      std::vector<double>                  eta_sum(n_points, 0.), count(n_points, 0.);
      std::vector<types::global_dof_index> sdofs(fe_s.n_dofs_per_cell());
      for (const auto &cell : dof_s.active_cell_iterators())
        {
          double mean = 0.;
          for (unsigned int q = 0; q < nq; ++q)
            mean += eta[cell->active_cell_index() * nq + q] / nq;
          cell->get_dof_indices(sdofs);
          for (unsigned int k = 0; k < 3; ++k)
            {
              const std::size_t i = p1d ? cell->active_cell_index() * 3 + k : sdofs[k];
              eta_sum[i] += mean;
              count[i] += 1.;
            }
        }
      data.gamma_scale.resize(n_points);
      for (std::size_t i = 0; i < n_points; ++i)
        data.gamma_scale[i] = eta_sum[i] / count[i] / (prm.rheology.Re * point_weight[i]);
    }

    void
    Problem::make_mesh()
    {
      const auto &g   = prm.geometry;
      const auto  msh = out.file("mesh.msh");
      const auto &f   = prm.case_file;
      for (const auto &message : prm.ignored_geometry_entries())
        report.warn(message);
      // A fine mesh (1.5 million triangles at Mesh size 0.01 on the silo) took minutes without a
      // line on the console.
      mesh.before_meshing = [&](const double triangles) {
        if (triangles > 2e5)
          {
            std::ostringstream s;
            s << std::setprecision(2) << "meshing the " << g.shape << ": about " << triangles
              << " triangles at Geometry/Mesh size = " << g.mesh_size << "\n";
            log.print(s.str());
          }
      };
      if (g.shape == "channel")
        geometry::make_channel(mesh, g.channel_length, g.channel_width, g.mesh_size, msh, f);
      else if (g.shape == "square patch")
        geometry::make_square_patch(mesh, g.patch_size, g.mesh_size, msh, f);
      else if (g.shape == "half silo")
        geometry::make_half_silo(mesh, g.silo_width, g.silo_height, g.aperture, g.outlet_extension,
                                 g.mesh_size, msh, f);
      else if (g.shape == "cylinder channel")
        geometry::make_cylinder_channel(mesh, g.channel_length, g.channel_width, g.cylinder_diameter,
                                        g.mesh_size, msh, f);
      else
        {
          geometry::read_mesh_file(mesh, g.mesh_file, f);
          // The output directory keeps the mesh the run used, as for the generated shapes.
          std::error_code ec;
          std::filesystem::copy_file(g.mesh_file, msh,
                                     std::filesystem::copy_options::overwrite_existing, ec);
          if (ec)
            report.warn("the mesh file " + g.mesh_file +
                        " could not be copied into the output directory (" + ec.message() +
                        "); the run goes on with the mesh read from it");
        }
      if (g.refinements > 0)
        {
          // New vertices on the cylinder go onto the circle, not onto the chords of the coarse
          // mesh (the generator centres the cylinder at the origin).
          if (g.shape == "cylinder channel")
            {
              const auto cylinder = mesh.id("cylinder", f);
              for (const auto &face : mesh.triangulation.active_face_iterators())
                if (face->at_boundary() && face->boundary_id() == cylinder)
                  face->set_manifold_id(1);
              mesh.triangulation.set_manifold(1, SphericalManifold<dim>(Point<dim>()));
            }
          // Each refinement quadruples the triangles; the generators' bound of 1e7 holds for the
          // refined mesh too.
          const double triangles =
              mesh.triangulation.n_active_cells() * std::pow(4., g.refinements);
          if (triangles > 1e7)
            {
              std::ostringstream s;
              s << "= " << g.refinements << " gives " << triangles << " triangles (from "
                << mesh.triangulation.n_active_cells() << "): expected at most 1e7";
              throw InputError(prm.case_file, "Geometry/Global refinements", s.str());
            }
          mesh.triangulation.refine_global(g.refinements);
        }
    }

    void
    Problem::setup()
    {
      dof_u.reinit(mesh.triangulation);
      dof_u.distribute_dofs(fe_u);
      dof_s.reinit(mesh.triangulation);
      dof_s.distribute_dofs(fe_s);
      apply_boundary_conditions();
      number_free_dofs();
      n_points = p1d ? mesh.triangulation.n_active_cells() * 3 : dof_s.n_dofs();
      u.reinit(dof_u.n_dofs());
      // The profile line must cross the domain: checked now, not after the solve. The default line
      // (the mesh's vertical middle line, which a U-shaped mesh or one with a hole may miss) is
      // not refused, only left out with a warning: the user did not ask for it.
      const auto [a, b] = profile_line();
      if (postprocess::sample_line(mapping, dof_u, u, a, b, prm.output.profile_points)
              .points.size() < 2)
        {
          if (prm.output.profile_start.empty())
            {
              std::ostringstream w;
              w << "no profiles/velocity.csv: the mesh's vertical middle line, (" << a[0] << ", "
                << a[1] << ") to (" << b[0] << ", " << b[1] << "), has fewer than 2 of its "
                << prm.output.profile_points
                << " points in the mesh; set Output/Profile start and end to a line across the "
                   "domain";
              report.warn(w.str());
            }
          else
            throw InputError(prm.case_file, "Output/Profile start",
                             "'" + prm.output.profile_start + "' to Output/Profile end '" +
                                 prm.output.profile_end + "': fewer than 2 of the line's " +
                                 std::to_string(prm.output.profile_points) +
                                 " points lie in the mesh: expected a line across the domain");
        }
      else
        profile.emplace(a, b);

      std::ostringstream s;
      s << "Mesh: " << mesh.triangulation.n_active_cells() << " triangles, "
        << mesh.triangulation.n_vertices() << " vertices; velocity P2: " << dof_u.n_dofs()
        << " dofs (" << n_free << " free); stress " << prm.solver.stress_element << ": " << n_points
        << " constraint points\n";
      log.print(s.str());

      note_unconditioned_and_unresolved_boundaries();
      prm.require_reference_boundaries();
      // Only the direction of gravity enters (23): the body force is rho g, in units of rho g.
      if (const Point<dim> g =
              parse_point(prm.gravity_direction, prm.case_file, "Gravity direction");
          std::abs(g.norm() - 1.) > 1e-12)
        {
          std::ostringstream   note;
          const Tensor<1, dim> e = prm.e_g();
          note << "dp: note: Gravity direction (" << g[0] << ", " << g[1] << ") has length "
               << g.norm() << "; only its direction (" << e[0] << ", " << e[1]
               << ") is used: the body force is rho g, the unit of (23)\n";
          log.print(note.str());
        }
    }

    void
    Problem::apply_boundary_conditions()
    {
      const auto &bc = prm.boundaries;
      // A name in two velocity conditions is a contradiction or a typo.
      const auto velocities =
          parse_named_velocities(bc.velocity, prm.case_file, "Boundary conditions/Velocity");
      std::vector<std::pair<std::string, const char *>> named; // (boundary, entry)
      for (const auto &[list, entry] : bc.velocity_conditions())
        for (const std::string &name : split_list(*list))
          named.emplace_back(name, entry);
      for (const auto &[name, value] : velocities)
        named.emplace_back(name, "Velocity");
      std::map<types::boundary_id, const char *> condition_of;
      for (const auto &[name, entry] : named)
        if (const auto [it, fresh] = condition_of.emplace(
                mesh.id(name, prm.case_file, std::string("Boundary conditions/") + entry), entry);
            !fresh)
          throw InputError(prm.case_file, std::string("Boundary conditions/") + entry,
                           "names '" + name + "', which is also in Boundary conditions/" +
                               it->second + ": expected one velocity condition per boundary");
      // u = value on boundary `name`, in the components of `mask`. A dof already fixed keeps its
      // value: the homogeneous conditions come first, so a moving lid's end nodes on no-slip
      // walls stay at rest, and of two Velocity boundaries the one listed first wins.
      const auto add = [&](const std::string &name, const char *entry, const ComponentMask &mask,
                           const Tensor<1, dim> &value) {
        const types::boundary_id                  id = mesh.id(name, prm.case_file, entry);
        std::map<types::global_dof_index, double> values;
        VectorTools::interpolate_boundary_values(
            mapping, dof_u, id,
            Functions::ConstantFunction<dim>(std::vector<double>{value[0], value[1]}), values,
            mask);
        dirichlet.insert(values.begin(), values.end());
        velocity_boundaries.push_back({id, mask});
      };
      for (const auto &[list, entry, mask] :
           {std::make_tuple(&bc.no_slip, "Boundary conditions/No-slip", ComponentMask()),
            std::make_tuple(&bc.zero_x_velocity, "Boundary conditions/Zero x-velocity",
                            ComponentMask(std::vector<bool>{true, false})),
            std::make_tuple(&bc.zero_y_velocity, "Boundary conditions/Zero y-velocity",
                            ComponentMask(std::vector<bool>{false, true}))})
        for (const std::string &name : split_list(*list))
          add(name, entry, mask, Tensor<1, dim>());
      for (const auto &[name, value] : velocities)
        add(name, "Boundary conditions/Velocity", ComponentMask(), value);
      constrain_directions();
      const std::vector<CellList> pieces = mesh_pieces();
      require_no_free_rigid_motion(pieces); // also where there is no velocity condition at all
      require_no_net_inflow_into_a_closed_domain(pieces);

      // Every named boundary of the load must exist too (checked before anything is solved).
      for (const auto &[name, p] :
           parse_named_values(bc.external_pressure, prm.case_file, "Boundary conditions/External pressure"))
        {
          external_pressures.emplace_back(
              mesh.id(name, prm.case_file, "Boundary conditions/External pressure"), p);
          const auto condition = condition_of.find(external_pressures.back().first);
          // A pressure does work only through the normal velocity (free on a Zero x-velocity
          // boundary y = const, for example).
          if (condition != condition_of.end() &&
              (std::string(condition->second) == "No-slip" ||
               std::string(condition->second) == "Velocity" ||
               std::string(condition->second) == "Zero normal velocity"))
            throw InputError(prm.case_file, "Boundary conditions/External pressure",
                             "on '" + name + "', a " + condition->second +
                                 " boundary, where the normal velocity is prescribed and a "
                                 "pressure does nothing: expected a boundary where the normal "
                                 "velocity is free");
        }
      const std::string stress_entry = "Boundary conditions/External stress";
      for (const auto &[name, sigma] :
           parse_named_stresses(bc.external_stress, prm.case_file, stress_entry))
        {
          const types::boundary_id id = mesh.id(name, prm.case_file, stress_entry);
          // The natural condition sigma_tot n = sigma_ext n (the sum of (20b) and (21)) holds on
          // B_N, where the velocity is free; where a velocity condition fixes some direction, the
          // reaction there would take up the stress's part along it.
          if (const auto condition = condition_of.find(id); condition != condition_of.end())
            throw InputError(prm.case_file, stress_entry,
                             "on '" + name + "', a " + condition->second +
                                 " boundary: expected a boundary with no velocity condition (for "
                                 "a normal load on a boundary with one velocity component fixed, "
                                 "use External pressure)");
          for (const auto &[pressed, p_ext] : external_pressures)
            if (pressed == id)
              throw InputError(prm.case_file, stress_entry,
                               "on '" + name +
                                   "', which is also in Boundary conditions/External pressure: "
                                   "expected one load per boundary (a pressure p is the stress "
                                   "(-p, 0, -p))");
          external_stresses.emplace_back(id, sigma);
        }
      warn_of_tension();
      for (const std::string &name : split_list(bc.analytic_traction))
        analytic_tractions.push_back(
            mesh.id(name, prm.case_file, "Boundary conditions/Analytic traction"));
      if (!prm.output.drag_boundary.empty())
        {
          // The force is the reaction where the velocity is constrained (boundary_force()).
          if (!condition_of.count(
                  mesh.id(prm.output.drag_boundary, prm.case_file, "Output/Drag boundary")))
            throw InputError(prm.case_file, "Output/Drag boundary",
                             "'" + prm.output.drag_boundary +
                                 "' has no velocity condition: expected a boundary in one of "
                                 "the velocity conditions of Boundary conditions (the force is "
                                 "its reaction)");
        }
      if (!prm.output.inflow_boundary.empty())
        mesh.id(prm.output.inflow_boundary, prm.case_file, "Output/Inflow boundary");
    }

    /// A granular material carries no tension: lambda_N >= 0 (the cone K_mu of (16)). A load
    /// that pulls on a boundary (a negative External pressure, an External stress with n .
    /// sigma_ext n > 0 on some face) is resisted only by the viscous stress 2/Re D^b(u), so the
    /// material there dilates (div u > 0); more often it is a sign written the wrong way (tension
    /// is positive in sigma_ext), hence the warning.
    void
    Problem::warn_of_tension()
    {
      const QGauss<dim - 1> face_quadrature(1);
      FEFaceValues<dim>     fvf(mapping, fe_u, face_quadrature, update_normal_vectors);
      const auto            largest_pull = [&](const types::boundary_id id, const auto &sigma) {
        double pull = -std::numeric_limits<double>::infinity();
        for_each_face_on(dof_u, id, fvf, [&](const auto &) {
          const Tensor<1, dim> n = fvf.normal_vector(0);
          pull                   = std::max(pull, n * (sigma * n));
        });
        return pull;
      };
      const auto warn = [&](const std::string &entry, const types::boundary_id id,
                            const double pull, const std::string &convention) {
        std::string name;
        for (const auto &[n, i] : mesh.boundary_ids)
          if (i == id)
            name = n;
        std::ostringstream w;
        w << std::setprecision(3) << "Boundary conditions/" << entry << " pulls on '" << name
          << "' (a normal traction of up to " << pull << " outwards; " << convention
          << "): the "
             "granular stress carries no tension (lambda_N >= 0), only the viscous stress "
             "2/Re D^b(u) resists it, and the material there dilates";
        report.warn(w.str());
      };
      for (const auto &[id, p_ext] : external_pressures)
        if (p_ext < 0.)
          warn("External pressure", id, -p_ext, "a negative pressure");
      for (const auto &[id, sigma] : external_stresses)
        if (const double pull = largest_pull(id, sigma); pull > 1e-12 * sigma.norm())
          warn("External stress", id, pull,
               "sigma_ext has tension positive, a pressure p is (-p, 0, -p)");
    }

    void
    Problem::number_free_dofs()
    {
      free_index.assign(dof_u.n_dofs(), -1);
      free_coefficient.assign(dof_u.n_dofs(), 1.);
      reaction_dof.assign(dof_u.n_dofs(), false);
      std::map<types::global_dof_index, types::global_dof_index> partner;
      for (const auto &[x, node] : directed_nodes)
        {
          // u = w t with t = d rotated by +90 degrees, its larger component positive (so that
          // d = +-e_x gives t = e_y, the same unknown as Zero x-velocity).
          Tensor<1, dim> t({-node.second[1], node.second[0]});
          if (std::abs(t[0]) >= std::abs(t[1]) ? t[0] < 0. : t[1] < 0.)
            t *= -1.;
          free_coefficient[x]          = t[0];
          free_coefficient[node.first] = t[1];
          partner[x]                   = node.first;
          partner[node.first]          = x;
          reaction_dof[x] = reaction_dof[node.first] = true;
        }
      for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
        if (dirichlet.count(i))
          reaction_dof[i] = true;
        else if (const auto p = partner.find(i); p != partner.end() && free_index[p->second] >= 0)
          free_index[i] = free_index[p->second];
        else
          free_index[i] = static_cast<int>(n_free++);
    }

    void
    Problem::note_unconditioned_and_unresolved_boundaries()
    {
      // What a user may not have meant: a named boundary in no condition is traction-free (the
      // material leaves through a forgotten floor), and a boundary of one mesh edge is not
      // resolved (a silo outlet narrower than the mesh size jams on the mesh, not on the
      // rheology).
      std::map<types::boundary_id, std::size_t> edges;
      for (const auto &face : mesh.triangulation.active_face_iterators())
        if (face->at_boundary())
          ++edges[face->boundary_id()];
      std::set<types::boundary_id> conditioned;
      for (const auto &vb : velocity_boundaries)
        conditioned.insert(vb.id);
      for (const auto &[id, p] : external_pressures)
        conditioned.insert(id);
      for (const auto &[id, sigma] : external_stresses)
        conditioned.insert(id);
      conditioned.insert(analytic_tractions.begin(), analytic_tractions.end());
      std::string free;
      for (const auto &[name, id] : mesh.boundary_ids)
        {
          if (!conditioned.count(id))
            {
              free += (free.empty() ? "'" : ", '") + name + "'";
              traction_free.push_back(name);
            }
          if (edges[id] <= 1)
            report.warn(
                "boundary '" + name + "' is " + std::to_string(edges[id]) +
                " mesh edge: the mesh does not resolve it; a flow through or along it (an outlet, "
                "a jam) is "
                "the mesh's, not the model's: refine Geometry/Mesh size");
        }
      if (!free.empty())
        log.print("dp: note: no condition on " + free +
                  ": traction-free (the material may leave or enter there)\n");
    }

    solvers::ConeSolverStats
    Problem::solve_cone_problem()
    {
      solvers::ConeSolverOptions options;
      options.method               = solvers::parse_cone_method(prm.solver.method);
      options.inner_solver         = solvers::parse_inner_solver(prm.solver.inner_solver);
      options.residual             = prm.solver.residual == "alart-curnier" ?
                                       solvers::ResidualKind::alart_curnier :
                                       solvers::ResidualKind::fischer_burmeister;
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
        try
          {
            // relative to the output directory, subdirectories included
            const std::filesystem::path dump = out.file(prm.solver.dump_cone_problem);
            std::filesystem::create_directories(dump.parent_path());
            write_file_atomically(dump.string(), [&](std::ostream &file) {
              solvers::write_cone_problem(data, file);
            });
          }
        catch (const std::exception &e)
          {
            throw InputError(
                prm.case_file, "Solver/Dump cone problem",
                "= " + prm.solver.dump_cone_problem + ": cannot be written (" + e.what() +
                    "; expected a file name, relative to the output directory, or a writable "
                    "path)");
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
                           "its velocity conditions (" +
                               velocity_condition_entries(prm.boundaries) +
                               ") leave a rigid motion of the velocity free (A is singular): "
                               "expected velocity conditions that fix both translations and the "
                               "rotation");
        }
      log.flush_table();

      for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
        u[i] =
            free_index[i] >= 0 ? free_coefficient[i] * solution.u[free_index[i]] : dirichlet.at(i);
      return stats;
    }

    /// Daviet 6.1.3: eta = |D(u)| = sqrt(D:D / 2) at the quadrature points of a(., .), bounded
    /// below by the viscosity floor (eta -> 0 at the free surface would make A singular).
    std::vector<double>
    Problem::viscosity_from_velocity() const
    {
      FEValues<dim> fv(mapping, fe_u, quadrature, update_gradients);
      const FEValuesExtractors::Vector        velocity(0);
      std::vector<SymmetricTensor<2, dim>>    D(quadrature.size());
      std::vector<double>                     eta;
      for (const auto &cell : dof_u.active_cell_iterators())
        {
          fv.reinit(cell);
          fv[velocity].get_function_symmetric_gradients(u, D);
          for (const auto &d : D)
            eta.push_back(bagnold_viscosity(d));
        }
      return eta;
    }

    double
    Problem::viscosity_change(const Vector<double> &u_old) const
    {
      FEValues<dim> fv(mapping, fe_u, quadrature, update_gradients | update_JxW_values);
      const FEValuesExtractors::Vector     velocity(0);
      std::vector<SymmetricTensor<2, dim>> D(quadrature.size()), D_old(quadrature.size());
      double                               change = 0., size = 0.;
      for (const auto &cell : dof_u.active_cell_iterators())
        {
          fv.reinit(cell);
          fv[velocity].get_function_symmetric_gradients(u, D);
          fv[velocity].get_function_symmetric_gradients(u_old, D_old);
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const double eta = bagnold_viscosity(D[q]), eta_old = bagnold_viscosity(D_old[q]);
              change += (eta - eta_old) * (eta - eta_old) * fv.JxW(q);
              size += eta * eta * fv.JxW(q);
            }
        }
      return std::sqrt(change / size); // eta >= the viscosity floor > 0
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

      const std::size_t n_qp = mesh.triangulation.n_active_cells() * quadrature.size();
      std::vector<double> eta(n_qp, 1.);
      const bool          bagnold = prm.rheology.viscosity == "bagnold";
      const bool          interior_point =
          solvers::parse_cone_method(prm.solver.method) == solvers::ConeMethod::interior_point;
      unsigned int        viscosity_iterations = 0;
      // not measured (null in summary.json) until a second Bagnold solve
      double                   change = std::numeric_limits<double>::quiet_NaN();
      solvers::ConeSolverStats stats;
      unsigned int outer_total = 0, inner_total = 0;
      double       solve_time = 0., factorize_time = 0.;
      for (;;)
        {
          assemble_velocity_operator(eta);
          set_residual_scale(eta);
          log.phase(interior_point ? "interior-point iterations (" + std::to_string(n_free) +
                                         " free velocity dofs; each factorises its Newton matrix)"
                                   : "factorising A (" + std::to_string(n_free) +
                                         " free velocity dofs), then fixed-point iterations");
          const Vector<double> u_old = u;
          stats = solve_cone_problem();
          before_results.reset();
          outer_total += stats.outer_iterations;
          inner_total += stats.inner_iterations;
          solve_time += stats.time_solve;
          factorize_time += stats.time_factorize;
          ++viscosity_iterations;
          std::ostringstream s;
          s << "  solve " << viscosity_iterations << ": " << stats.outer_iterations
            << (interior_point ? " interior-point" : " fixed-point") << " iterations, residual "
            << stats.residual << ", " << stats.time_solve << " s";
          if (!stats.converged || !bagnold)
            {
              log.print(s.str() + (stats.converged     ? "\n"
                                   : stats.interrupted ? " (interrupted)\n"
                                                       : " (not converged)\n"));
              break;
            }
          change = viscosity_change(u_old);
          s << ", viscosity fixed point: relative change of eta = |D(u)| " << change;
          log.print(s.str() + "\n");
          log.progress("viscosity iteration " + std::to_string(viscosity_iterations));
          if (change <= prm.solver.viscosity_tolerance ||
              viscosity_iterations == prm.solver.viscosity_iterations)
            break;
          // Geometric relaxation eta <- sqrt(eta |D(u)|): in a flowing layer the stress does not
          // depend on eta and u scales like 1/eta, so the plain update eta <- |D(u)| cycles
          // between two states; the geometric mean is its fixed point.
          const std::vector<double> eta_new = viscosity_from_velocity();
          for (std::size_t k = 0; k < eta.size(); ++k)
            eta[k] = std::sqrt(eta[k] * eta_new[k]);
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
        solver_json["interior_point_iterations"] = outer_total;
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
            << viscosity_iterations << " iterations (last relative change of eta = |D(u)| "
            << change << ", tolerance " << prm.solver.viscosity_tolerance
            << "): every result here is that of its last iterate, not of a solution";
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
            << " its tolerance (residual " << stats.residual << ", tolerance "
            << prm.solver.tolerance << (stats.stalled ? "; it stalled: " : "") << stats.stall_reason
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
      s << "the " << (interior_point ? "interior-point method" : "Cadoux fixed point");
      if (stats.interrupted)
        s << " was stopped by " << interrupt::signal_name() << " at residual " << stats.residual
          << " (tolerance " << prm.solver.tolerance << ") after " << stats.outer_iterations
          << " iterations. ";
      else if (stats.stalled)
        s << " stalled at residual " << stats.residual << " (tolerance " << prm.solver.tolerance
          << ") after " << stats.outer_iterations << " iterations: " << stats.stall_reason
          << " (docs/solvers.md), which higher limits do not change; a looser "
             "Solver/Tolerance, "
             "another mesh or Solver/Method = fixed point may. ";
      else if (stats.timed_out)
        s << " was stopped by Solver/Max seconds = " << prm.solver.max_seconds << " at residual "
          << stats.residual << " (tolerance " << prm.solver.tolerance << ") after "
          << stats.outer_iterations << " iterations. ";
      else
        {
          s << " did not reach the tolerance " << prm.solver.tolerance << " (residual "
            << stats.residual << " after " << stats.outer_iterations << " iterations";
          // A fixed point whose second half of iterations did not halve the least residual
          // of the first oscillates or crawls (the Bagnold layer at tan alpha = 0.7: between
          // 2.5e-5 and 5e-5 for 450 iterations, where the interior point converges in 9 s),
          // and higher limits are no remedy.
          const auto  &history = stats.residual_history;
          const size_t half    = history.size() / 2;
          double       first = 0., second = 0.;
          bool         stagnating = false;
          if (!interior_point && history.size() >= 20)
            {
              first      = *std::min_element(history.begin(), history.begin() + half);
              second     = *std::min_element(history.begin() + half, history.end());
              stagnating = second > 0.5 * first;
            }
          if (stagnating)
            {
              s << "; over its last " << history.size() - half << " iterations the least residual ";
              if (second < first)
                s << "fell only from " << first << " to " << second;
              else // rising ("fell from 1.8 to 11" read as a misprint)
                s << "did not fall below " << first << ", the least of the first " << half
                  << " (the least of the last " << history.size() - half << " was " << second
                  << ")";
              s << ", so higher limits will not help";
              if (prm.rheology.Bi == 0. && prm.rheology.mu > 0.)
                s << "; Solver/Method = interior point may). ";
              else
                s << "). ";
            }
          else
            s << "; raise "
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

    /// Fields at the constraint points (stress lambda; discrete strain rate gamma / (2 w_i), the
    /// chi-coordinates of D(u) the rheology sees) and the zones; sets stress_fields and cell_zone.
    Problem::PointFields
    Problem::point_fields()
    {
      const double sqrt_2_over_d = std::sqrt(2. / dim); // p = sqrt(2/d) lambda_N (Property 2)
      PointFields          pf;
      std::vector<double> &p = pf.p, &div_u = pf.div_u, &D0_norm = pf.D0_norm, &zone = pf.zone;
      for (std::vector<double> *v : {&p, &div_u, &D0_norm, &zone})
        v->resize(n_points);
      std::vector<double> tau_xx(n_points), tau_xy(n_points), lambda_N(n_points),
          lambda_1(n_points), lambda_2(n_points), D0_1(n_points), D0_2(n_points),
          residual(n_points);
      double &max_D0 = pf.max_D0, &max_div = pf.max_div;
      for (std::size_t i = 0; i < n_points; ++i)
        {
          const double *l = &solution.lambda[i * s_d], *g = &solution.gamma[i * s_d];
          const double  w = 2. * point_weight[i];
          lambda_N[i] = l[0];
          lambda_1[i] = l[1];
          lambda_2[i] = l[2];
          p[i]        = sqrt_2_over_d * l[0];
          tau_xx[i]   = -l[1]; // tau = -Dev(lambda), chi(0; b, c) = [[b, c], [c, -b]]
          tau_xy[i]   = -l[2];
          D0_1[i]         = g[1] / w;
          D0_2[i]         = g[2] / w;
          D0_norm[i]      = std::hypot(D0_1[i], D0_2[i]);
          div_u[i]    = std::sqrt(2. * dim) * g[0] / w;
          max_D0      = std::max(max_D0, D0_norm[i]);
          // Where the solver's residual is largest (the rheology is violated by this much).
          const double    c = data.gamma_scale[i];
          const SymVector lv{{l[0], l[1], l[2]}}, gv{{c * g[0], c * g[1], c * g[2]}};
          residual[i] = rheology::norm(
            prm.solver.residual == "alart-curnier" || prm.rheology.Bi > 0. ?
              rheology::f_AC(lv, gv, prm.rheology.mu, prm.rheology.Bi) :
              rheology::f_FB(lv, gv, prm.rheology.mu));
          max_div     = std::max(max_div, div_u[i]);
        }
      // Zones, judged on the scaled strain rate c_i gamma_i the solver's residual measures (the
      // viscous stress 2/Re D): rigid where its tangential part is zero to the solver tolerance
      // (in a rigid zone the Alart-Curnier residual is exactly -gamma_T), dilating where its
      // normal part exceeds it, flowing otherwise. In |D0| this threshold is 10 tol Re / 2 at
      // every point; summary.json reports it.
      const double threshold = pf.threshold = 10. * prm.solver.tolerance;
      std::size_t &n_rigid = pf.n_rigid, &n_flowing = pf.n_flowing, &n_dilating = pf.n_dilating;
      double      &rigid_D0_min = pf.rigid_D0_min, &rigid_D0_max = pf.rigid_D0_max;
      for (std::size_t i = 0; i < n_points; ++i)
        {
          const double c    = data.gamma_scale[i];
          rigid_D0_min      = std::min(rigid_D0_min, threshold / (2. * point_weight[i] * c));
          rigid_D0_max      = std::max(rigid_D0_max, threshold / (2. * point_weight[i] * c));
          const double g[3] = {c * solution.gamma[i * s_d], c * solution.gamma[i * s_d + 1],
                               c * solution.gamma[i * s_d + 2]};
          if (g[0] > threshold)
            zone[i] = 2, ++n_dilating;
          else if (std::hypot(g[1], g[2]) <= threshold)
            zone[i] = 0, ++n_rigid;
          else
            zone[i] = 1, ++n_flowing;
        }

      // Point values -> stress-space fields. P1d: a quantity linear in lambda or D(u) is the linear
      // function through the 3 points (the discrete stress and strain rate themselves, whose
      // vertex values may leave the cone: only the points are constrained); a norm is taken of
      // those vertex values, not extrapolated (which made it negative); the residual
      // is the value of the point nearest each vertex (point k sits on the median from vertex k,
      // constraint_rule()). The zone is one value per triangle, that of two or three of its
      // points (flowing if all three differ), so that it stays 0, 1 or 2 in the VTU.
      std::vector<types::global_dof_index> sdofs(fe_s.n_dofs_per_cell());
      const auto to_field = [&](const std::vector<double> &values, const bool linear) {
        Vector<double> field(dof_s.n_dofs());
        if (!p1d)
          {
            std::copy(values.begin(), values.end(), field.begin());
            return field;
          }
        for (const auto &cell : dof_s.active_cell_iterators())
          {
            cell->get_dof_indices(sdofs);
            const std::size_t           base = cell->active_cell_index() * 3;
            const std::array<double, 3> at_points{
                {values[base], values[base + 1], values[base + 2]}};
            const std::array<double, 3> v =
                linear ? vertex_values_from_points(at_points) : at_points;
            for (unsigned int k = 0; k < 3; ++k)
              field[sdofs[k]] = v[k];
          }
        return field;
      };
      const auto norm_of = [](const Vector<double> &a, const Vector<double> &b) {
        Vector<double> n(a.size());
        for (unsigned int i = 0; i < a.size(); ++i)
          n[i] = std::hypot(a[i], b[i]);
        return n;
      };
      stress_fields = {
          {"pressure", to_field(p, true)},        {"tau_xx", to_field(tau_xx, true)},
          {"tau_xy", to_field(tau_xy, true)},     {"div_u", to_field(div_u, true)},
          {"lambda_N", to_field(lambda_N, true)}, {"lambda_1", to_field(lambda_1, true)},
          {"lambda_2", to_field(lambda_2, true)}, {"residual", to_field(residual, false)}};
      stress_fields["tau_norm"] = norm_of(stress_fields["tau_xx"], stress_fields["tau_xy"]);
      stress_fields["D0_norm"]  = norm_of(to_field(D0_1, true), to_field(D0_2, true));
      cell_zone.reinit(mesh.triangulation.n_active_cells());
      for (const auto &cell : dof_s.active_cell_iterators())
        {
          cell->get_dof_indices(sdofs);
          std::array<int, 3> count{{0, 0, 0}};
          for (unsigned int k = 0; k < 3; ++k)
            ++count[static_cast<int>(zone[p1d ? cell->active_cell_index() * 3 + k : sdofs[k]])];
          const auto most                      = std::max_element(count.begin(), count.end());
          cell_zone[cell->active_cell_index()] = *most >= 2 ? most - count.begin() : 1;
        }
      return pf;
    }

    /// The warnings on what the zones can tell at this tolerance.
    void
    Problem::warn_about_zones(const PointFields &pf)
    {
      // The zones separate rigid from flowing material only down to the rigid threshold, which
      // the tolerance sets. A loose tolerance (a stalled run's remedy) makes slowly shearing
      // material "rigid": a silo at Solver/Tolerance = 1e-2 had its whole bulk rigid, the
      // threshold being 22 % of its largest strain rate (the default cylinder: 2e-5). Without
      // rigid points there is nothing to mislabel (the Bagnold layer, whose eta = abs D makes
      // the threshold large at its free surface).
      // A body at rest (a closed silo) has a unique velocity, 0, but not a unique stress (4.4.4):
      // any admissible field in equilibrium with the loads is a solution, and the method picks
      // one (a closed silo's floor carried 43.1 with the interior point, 51.0 with the fixed
      // point, of a weight of 64.5).
      const bool all_rigid = pf.n_rigid > 0 && pf.n_flowing == 0 && pf.n_dilating == 0;
      if (all_rigid)
        {
          std::ostringstream w;
          w << std::setprecision(3)
            << "the material is rigid at every point (each point's abs D0 is below its rigid "
               "threshold, at least "
            << pf.rigid_D0_min << "; the largest abs D0 is " << pf.max_D0 << "): ";
          // At rest the strain rates are the solver's noise, far below the threshold (a closed
          // silo at 1e-6: 3 % of it); within a decade of it, a slow flow is counted rigid (the
          // shipped silo at a tolerance of 5e-2, which discharges, has every point "rigid").
          if (pf.max_D0 > 0.1 * pf.rigid_D0_min)
            w << "the strain rates are within a decade of the threshold, so a slow flow cannot be "
                 "told from rest at Solver/Tolerance = "
              << prm.solver.tolerance << " (lower it: README, Output directory); ";
          w << "where the body is rigid the velocity is unique, the stress is not (4.4.4): p, tau "
               "and the boundary forces are one admissible field in equilibrium with the loads, "
               "which the method picks (the fixed point and the interior point differ)";
          report.warn(w.str());
        }
      // (a body rigid everywhere has no flow to separate: the warning above covers it)
      if (!all_rigid && pf.n_rigid > 0 && pf.max_D0 > 0. && pf.rigid_D0_max > 0.01 * pf.max_D0)
        {
          std::ostringstream w;
          w << std::setprecision(3)
            << "the zones cannot separate rigid from slowly flowing material: 'rigid' means abs "
               "D0 below "
            << pf.rigid_D0_max << ", " << 100. * pf.rigid_D0_max / pf.max_D0
            << " % of the largest abs D0 (" << pf.max_D0
            << "), because of Solver/Tolerance = " << prm.solver.tolerance
            << "; lower the tolerance for a zone map (README, Output directory)";
          report.warn(w.str());
        }
    }

    std::pair<Point<dim>, Point<dim>>
    Problem::profile_line() const
    {
      if (!prm.output.profile_start.empty())
        return {parse_point(prm.output.profile_start, prm.case_file, "Output/Profile start"),
                parse_point(prm.output.profile_end, prm.case_file, "Output/Profile end")};
      const auto   box = GridTools::compute_bounding_box(mesh.triangulation);
      const double x_mid =
          (box.get_boundary_points().first[0] + box.get_boundary_points().second[0]) / 2.;
      return {Point<dim>(x_mid, box.get_boundary_points().first[1]),
              Point<dim>(x_mid, box.get_boundary_points().second[1])};
    }

    /// profiles/velocity.csv along the case's line, and the errors against the analytic reference.
    void
    Problem::write_velocity_profile(nlohmann::json &S, const PointFields &pf)
    {
      const std::vector<double> &D0_norm   = pf.D0_norm;
      const double               max_D0    = pf.max_D0;
      const double               threshold = pf.threshold;
      if (!profile)
        return;
      const auto [a, b]  = *profile;
      S["profile_line"]  = {{"start", {a[0], a[1]}}, {"end", {b[0], b[1]}}};
      const auto samples = postprocess::sample_line(mapping, dof_u, u, a, b, prm.output.profile_points);
      // First column: the coordinate that varies along the line (y for a vertical line).
      const unsigned int axis = std::abs(b[1] - a[1]) >= std::abs(b[0] - a[0]) ? 1 : 0;
      std::vector<double> coord, ux, uy, shear;
      for (std::size_t k = 0; k < samples.points.size(); ++k)
        {
          coord.push_back(samples.points[k][axis]);
          ux.push_back(samples.values[k][0]);
          uy.push_back(samples.values[k][1]);
          shear.push_back(samples.gradients[k][0][1]); // du_x/dy
        }
      std::vector<std::string>         header = {axis ? "y" : "x", "u_x", "u_y", "du_x/dy"};
      std::vector<std::vector<double>> columns = {coord, ux, uy, shear};

      const std::string &reference = prm.output.reference;
      if (reference != "none")
        {
          std::vector<double> u_ref, shear_ref;
          const double        Bi = prm.rheology.Bi, Re = prm.rheology.Re, mu = prm.rheology.mu;
          const double        alpha = std::atan2(prm.e_g()[0], -prm.e_g()[1]);
          for (const double y : coord)
            if (reference == "bingham poiseuille")
              {
                u_ref.push_back(analytic::bingham_poiseuille_velocity(y, Bi, Re));
                shear_ref.push_back(analytic::bingham_poiseuille_shear_rate(y, Bi, Re));
              }
            else
              {
                u_ref.push_back(analytic::bagnold_velocity(y, mu, alpha, Re));
                shear_ref.push_back(analytic::bagnold_shear_rate(y, mu, alpha, Re));
              }
          double max_err = 0., max_ref = 0., max_shear_err = 0., max_shear_ref = 0.;
          for (std::size_t k = 0; k < coord.size(); ++k)
            {
              max_err       = std::max(max_err, std::abs(ux[k] - u_ref[k]));
              max_ref       = std::max(max_ref, std::abs(u_ref[k]));
              max_shear_err = std::max(max_shear_err, std::abs(shear[k] - shear_ref[k]));
              max_shear_ref = std::max(max_shear_ref, std::abs(shear_ref[k]));
            }
          header.insert(header.end(), {"u_x_reference", "du_x/dy_reference"});
          columns.push_back(u_ref);
          columns.push_back(shear_ref);
          S["reference"]           = reference;
          S["max_rel_error"]       = max_err / max_ref;
          S["max_rel_error_shear"] = max_shear_err / max_shear_ref;
          if (reference == "bingham poiseuille")
            {
              // The plug must be rigid: at the constraint points farther than two elements from
              // the analytic yield surface |y| = Bi (the discrete yield surface is only O(h)
              // accurate), ||gamma_T|| (the tangential Alart-Curnier residual there) and D0(u)
              // vanish to the solver tolerance.
              double h = 0.; // longest edge (cell->diameter() is for hypercubes in 9.4)
              for (const auto &cell : mesh.triangulation.active_cell_iterators())
                for (unsigned int e = 0; e < 3; ++e)
                  h = std::max(h, cell->vertex(e).distance(cell->vertex((e + 1) % 3)));
              double       plug_gamma_T = 0., plug_D0 = 0.;
              std::size_t  plug_points = 0;
              for (std::size_t i = 0; i < n_points; ++i)
                if (std::abs(point_location[i][1]) < Bi - 2. * h)
                  {
                    plug_gamma_T =
                        std::max(plug_gamma_T,
                                 data.gamma_scale[i] * std::hypot(solution.gamma[i * s_d + 1],
                                                                  solution.gamma[i * s_d + 2]));
                    plug_D0      = std::max(plug_D0, D0_norm[i]);
                    ++plug_points;
                  }
              // Daviet Fig. 5: errors over the whole domain against the analytic profile, in the
              // max norm and the H1 seminorm (at the points of a degree-6 rule).
              QGaussSimplex<dim> q_err(4);
              FEValues<dim>      fv(mapping, fe_u, q_err,
                               update_values | update_gradients | update_quadrature_points |
                                 update_JxW_values);
              std::vector<Vector<double>>              uq(q_err.size(), Vector<double>(dim));
              std::vector<std::vector<Tensor<1, dim>>> gq(q_err.size(),
                                                          std::vector<Tensor<1, dim>>(dim));
              double error_Linf = 0., error_H1_sq = 0.;
              for (const auto &cell : dof_u.active_cell_iterators())
                {
                  fv.reinit(cell);
                  fv.get_function_values(u, uq);
                  fv.get_function_gradients(u, gq);
                  for (unsigned int q = 0; q < q_err.size(); ++q)
                    {
                      const double y = fv.quadrature_point(q)[1];
                      const double e = analytic::bingham_poiseuille_velocity(y, Bi, Re) - uq[q][0];
                      error_Linf     = std::max({error_Linf, std::abs(e), std::abs(uq[q][1])});
                      Tensor<1, dim> de = gq[q][0];
                      de[1] -= analytic::bingham_poiseuille_shear_rate(y, Bi, Re);
                      error_H1_sq += (de * de + gq[q][1] * gq[q][1]) * fv.JxW(q);
                    }
                }
              S["error_Linf"] = error_Linf;
              S["error_H1"]   = std::sqrt(error_H1_sq);
              // Near Bi = 1 the sheared layer 1 - Bi by each wall is thinner than the elements,
              // and the discrete channel is nearly rigid: at the default mesh (longest edge h)
              // Bi = 0.95 is 2.5 % off, 0.98 21 %, 0.99 87 %, with the solver converged.
              if (Bi < 1. && 1. - Bi < 1.5 * h)
                {
                  std::ostringstream w;
                  w << std::setprecision(3)
                    << "the sheared layer by each wall, 1 - Bi = " << 1. - Bi << ", spans "
                    << (1. - Bi) / h << " elements (longest edge h = " << h
                    << "): the mesh does not resolve it, and max_rel_error is " << max_err / max_ref
                    << "; refine (Geometry/Mesh size or Global refinements)";
                  report.warn(w.str());
                }
              S["plug"] = {{"points", plug_points},
                           {"max_scaled_strain_rate_T", plug_gamma_T},
                           {"rigid_threshold", threshold},
                           {"max_deviatoric_strain_rate", plug_D0},
                           {"relative_to_max", plug_D0 / std::max(max_D0, 1e-300)}};
            }
        }
      out.write_csv("profiles/velocity.csv", header, columns);
    }

    /// The volume flux out through each named boundary, the rate of dilation and the domain's area.
    std::map<types::boundary_id, postprocess::BoundaryFlux>
    Problem::summarise_fluxes(nlohmann::json &S) const
    {
      std::map<types::boundary_id, postprocess::BoundaryFlux> flux_of;
      // Volume flux out through each named boundary (per unit depth; negative where material
      // enters): a silo's discharge rate is its outlet's. Their sum is int div u, the rate at
      // which the material dilates (div u >= 0 where it loses contact, Daviet 2.2).
      {
        nlohmann::json outflow = nlohmann::json::object();
        double         total   = 0.;
        for (const auto &[name, id] : mesh.boundary_ids)
          {
            flux_of[id]   = postprocess::boundary_normal_flux(mapping, dof_u, u, id);
            outflow[name] = flux_of[id].flux;
            total += flux_of[id].flux;
          }
        S["volume_outflow"]       = outflow;
        S["volume_outflow_total"] = total;
        FEValues<dim> fv(mapping, fe_u, quadrature, update_gradients | update_JxW_values);
        const FEValuesExtractors::Vector velocity(0);
        std::vector<double>              div(quadrature.size());
        double                           dilation = 0., area = 0.;
        for (const auto &cell : dof_u.active_cell_iterators())
          {
            fv.reinit(cell);
            fv[velocity].get_function_divergences(u, div);
            for (unsigned int q = 0; q < quadrature.size(); ++q)
              {
                dilation += div[q] * fv.JxW(q);
                area += fv.JxW(q);
              }
          }
        S["dilation_rate"] = dilation;
        // the domain's area per unit depth, in the same pass (GridTools::volume takes a quadrature
        // of the square, which doubles it on triangles in deal.II 9.4)
        S["mesh"]["area"] = area;
      }
      return flux_of;
    }

    /// U_infinity, the force on Output/Drag boundary and, in the cylinder channel, the wake, the
    /// arch, Fr and C_D (Daviet 6.3).
    Problem::Inflow
    Problem::summarise_inflow(
        nlohmann::json &S, const std::map<types::boundary_id, postprocess::BoundaryFlux> &flux_of)
    {
      Inflow result;
      if (prm.output.inflow_boundary.empty())
        return result;
      // Below jammed_speed the channel is jammed: 1e-5 Re sqrt(g L) (velocities scale with Re,
      // (23)); at the sweep's Re = 100 that is 1e-3, as in scripts/cylinder_drag_sweep.sh (its
      // jammed channels creep at the solver's accuracy in u, its slowest flowing one has 0.43).
      const double jammed_speed = 1e-5 * prm.rheology.Re;
      const auto &inflow = flux_of.at(mesh.id(prm.output.inflow_boundary, prm.case_file));
      result.U_inf       = -inflow.flux / inflow.length;
      result.u_x         = inflow.mean_u_x;
      S["U_infinity"]    = result.U_inf;
      result.jammed             = std::abs(result.U_inf) < jammed_speed;
      // Material leaving through the named inflow boundary (the flow runs the other way):
      // U_infinity measured there is the outflow's, which the material's dilation makes
      // larger than the inflow's (1.66 times in the mirrored cylinder channel), so Fr and C_D
      // would be wrong with exit 0; they are null, and the boundary where it enters is named.
      if (result.U_inf < -jammed_speed)
        {
          std::string entering;
          double      least = 0.;
          for (const auto &[name, id] : mesh.boundary_ids)
            if (flux_of.at(id).flux < least)
              least = flux_of.at(id).flux, entering = name;
          std::ostringstream w;
          w << std::setprecision(4) << "Output/Inflow boundary = '" << prm.output.inflow_boundary
            << "': the material leaves through it (volume flux " << inflow.flux
            << " out), so U_infinity there is an outflow's; Froude and drag_coefficient are "
               "null"
            << (entering.empty() ? std::string()
                                 : "; the material enters through '" + entering +
                                       "': set Output/Inflow boundary = " + entering);
          report.warn(w.str());
          result.reversed = true;
        }
      return result;
    }

    double
    Problem::rigid_fraction_next_to(const types::boundary_id   id,
                                    const std::vector<double> &zone) const
    {
      std::size_t                          touching = 0, rigid = 0;
      std::vector<types::global_dof_index> sdofs(fe_s.n_dofs_per_cell());
      for (const auto &cell : dof_s.active_cell_iterators())
        {
          bool on_boundary = false;
          for (const unsigned int f : cell->face_indices())
            on_boundary =
                on_boundary || (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == id);
          if (!on_boundary)
            continue;
          cell->get_dof_indices(sdofs);
          for (unsigned int k = 0; k < 3; ++k)
            {
              const std::size_t i = p1d ? cell->active_cell_index() * 3 + k : sdofs[k];
              ++touching;
              rigid += zone[i] == 0;
            }
        }
      return double(rigid) / std::max<std::size_t>(touching, 1);
    }

    void
    Problem::summarise_drag(nlohmann::json &S, const PointFields &pf,
                            const std::map<types::boundary_id, postprocess::BoundaryFlux> &flux_of)
    {
      const Inflow inflow = summarise_inflow(S, flux_of);
      if (prm.output.drag_boundary.empty())
        return;
      // The material's force on the boundary, int (lambda - 2/Re eta D^b(u)) n (23), from the
      // reaction; the paper's drag F_D = int lambda n . e_x (6.3.1) is that minus the viscous
      // traction, which the P2 velocity gives accurately.
      const auto           id      = mesh.id(prm.output.drag_boundary, prm.case_file);
      const Tensor<1, dim> force   = boundary_force(id);
      const Tensor<1, dim> viscous = viscous_traction_force(id);
      const double         F_D     = force[0] + viscous[0];
      S["drag"]                    = F_D;
      S["boundary_force"]          = {force[0], force[1]};
      S["boundary_force_viscous"]  = {-viscous[0], -viscous[1]};
      // Only the velocity is unique (4.4.4): where the material is rigid, any stress inside
      // the cones that balances the loads will do, and the methods pick different ones (the
      // silo's wall: vertical force +8.7 from the interior point, -5.8 from the fixed
      // point). The force on a boundary that rigid material touches is then not determined.
      const double rigid_fraction  = rigid_fraction_next_to(id, pf.zone);
      S["boundary_rigid_fraction"] = rigid_fraction;
      if (rigid_fraction > 0.1)
        {
          // a warning, so that summary.json, where the force is read, says it too
          std::ostringstream w;
          w << std::setprecision(3) << 100. * rigid_fraction
            << " % of the constraint points next to '" << prm.output.drag_boundary
            << "' are rigid; the stress in a rigid zone is not unique (only the velocity is, "
               "Daviet 4.4.4), so boundary_force and drag are not determined by the model "
               "there and depend on the solver";
          report.warn(w.str());
        }
      // The trace of the stress field, lambda n = (lambda_xx n_x + lambda_xy n_y) with lambda =
      // chi(lambda_N; lambda_1, lambda_2) = [[N + l1, l2], [l2, N - l1]]: the earlier estimate,
      // kept for comparison. It is constrained only at its points; with P1d it moved by 50 %
      // under refinement of the cylinder channel.
      Vector<double> l_xx = stress_fields["lambda_N"], l_xy = stress_fields["lambda_2"];
      l_xx += stress_fields["lambda_1"];
      S["drag_from_stress_trace"] = postprocess::boundary_flux(mapping, dof_s, l_xx, id)[0] +
                                    postprocess::boundary_flux(mapping, dof_s, l_xy, id)[1];
      // The wake, the arch, Fr and C_D are those of the cylinder channel's cylinder (its
      // diameter, centred at the origin): Daviet 6.3.2 (Fig. 14) and 6.3.1.
      if (prm.geometry.shape != "cylinder channel" || prm.output.drag_boundary != "cylinder")
        return;
      // The flow runs along +x or -x, as u_x does through the inflow boundary (whichever
      // end of the channel that is, and whichever way through it): the wake is behind the
      // cylinder along the flow. A jammed channel has no direction and no dynamic pressure to
      // scale C_D by.
      const double along = inflow.u_x < 0. && !inflow.jammed ? -1. : 1.;
      summarise_cylinder_wake(S, pf, along);
      if (inflow.reversed)
        {
          S["Froude"]           = nullptr;
          S["drag_coefficient"] = nullptr;
        }
      else if (!prm.output.inflow_boundary.empty())
        {
          const double D = prm.geometry.cylinder_diameter;
          S["Froude"]    = std::abs(inflow.U_inf) / std::sqrt(D);
          // C_D of the drag along the flow
          if (inflow.jammed)
            {
              S["drag_coefficient"] = nullptr;
              S["jammed"]           = true;
              log.print("dp: note: the flow is jammed (U_infinity = " +
                        std::to_string(inflow.U_inf) + "): drag_coefficient is null\n");
            }
          else
            S["drag_coefficient"] = along * F_D / (0.5 * inflow.U_inf * inflow.U_inf * D);
        }
    }

    void
    Problem::summarise_cylinder_wake(nlohmann::json &S, const PointFields &pf,
                                     const double along) const
    {
      const std::vector<double> &p     = pf.p;
      const std::vector<double> &div_u = pf.div_u;
      // The wake (one diameter behind the cylinder, |y| < D/2) has zero pressure and positive
      // divergence; the pressure peak on the centreline upstream (the arch) is located.
      const double                          R      = 0.5 * prm.geometry.cylinder_diameter;
      double                                wake_p = 0., wake_div = 0., wake_min_div = 1e300;
      std::size_t                           wake_points = 0;
      std::map<int, std::pair<double, int>> centreline; // bins of width R/4 upstream
      for (std::size_t i = 0; i < n_points; ++i)
        {
          const Point<dim> &y = point_location[i];
          const double      x = along * y[0]; // downstream coordinate
          if (x > R && x < 3. * R && std::abs(y[1]) < R)
            {
              wake_p = std::max(wake_p, p[i]);
              wake_div += div_u[i];
              wake_min_div = std::min(wake_min_div, div_u[i]);
              ++wake_points;
            }
          if (x < -R && std::abs(y[1]) < 0.25 * R)
            {
              auto &bin = centreline[static_cast<int>(std::floor(x / (0.25 * R)))];
              bin.first += p[i];
              ++bin.second;
            }
        }
      double peak_x = 0., peak_p = -1.;
      for (const auto &[bin, sum] : centreline)
        if (sum.first / sum.second > peak_p)
          {
            peak_p = sum.first / sum.second;
            peak_x = (bin + 0.5) * 0.25 * R;
          }
      // (null where no constraint point falls in the window: a channel that ends within a
      // diameter of the cylinder)
      const auto measured = [](const bool any, const double value) {
        return any ? nlohmann::json(value) : nlohmann::json(nullptr);
      };
      S["wake"]                   = {{"points", wake_points},
                                     {"max_pressure", measured(wake_points > 0, wake_p)},
                                     {"mean_div_u", measured(wake_points > 0, wake_div / double(wake_points))},
                                     {"min_div_u", measured(wake_points > 0, wake_min_div)}};
      S["upstream_pressure_peak"] = {{"x", measured(!centreline.empty(), along * peak_x)},
                                     {"mean_pressure", measured(!centreline.empty(), peak_p)},
                                     {"distance_from_cylinder_over_D",
                                      measured(!centreline.empty(), (-peak_x - R) / (2. * R))}};
    }

    /// Fields at the constraint points, the zones, profiles, fluxes, drag and errors against the
    /// analytic reference: summary.json, profiles/ and the stress-space fields of the VTU.
    void
    Problem::postprocess(Results &results)
    {
      const PointFields          pf           = point_fields();
      nlohmann::json            &S            = results.summary;
      S["traction_free_boundaries"]           = traction_free;
      S["case"]                               = prm.name;
      S["case_file"]                          = prm.case_file;
      S["model"]                              = "dp";
      // Daviet (23): the results are dimensionless in these units (L the case's length unit, g
      // gravity, rho the density; the timings are in seconds); 2D, so fluxes and forces are per
      // unit depth.
      S["units"]    = {{"length", "L"},
                       {"velocity", "sqrt(g L)"},
                       {"stress", "rho g L"},
                       {"volume_outflow", "L sqrt(g L) per unit depth"},
                       {"dilation_rate", "L sqrt(g L) per unit depth"},
                       {"force", "rho g L^2 per unit depth"}};
      S["rheology"] = {{"mu", prm.rheology.mu},
                       {"Bi", prm.rheology.Bi},
                       {"Re", prm.rheology.Re},
                       {"b", prm.rheology.b},
                       {"viscosity", prm.rheology.viscosity}};
      S["mesh"]     = {{"triangles", mesh.triangulation.n_active_cells()},
                       {"vertices", mesh.triangulation.n_vertices()},
                       {"velocity_dofs", dof_u.n_dofs()},
                       {"free_velocity_dofs", n_free},
                       {"stress_element", prm.solver.stress_element},
                       {"constraint_points", n_points}};
      S["solver"]   = solver_json;
      // as in the ngf summary: whether the run reached its tolerance, and whether a signal ended it
      S["converged"]   = solver_json.value("converged", false);
      S["interrupted"] = solver_json.value("interrupted", false);
      S["zones"]       = {{"rigid_points", pf.n_rigid},
                          {"flowing_points", pf.n_flowing},
                          {"dilating_points", pf.n_dilating},
                          {"max_div_u", pf.max_div},
                          {"max_deviatoric_strain_rate", pf.max_D0},
                          {"rigid_means_deviatoric_strain_rate_below",
                           {{"min", pf.rigid_D0_min}, {"max", pf.rigid_D0_max}}}};
      S["pressure"]    = {{"min", *std::min_element(pf.p.begin(), pf.p.end())},
                          {"max", *std::max_element(pf.p.begin(), pf.p.end())}};
      warn_about_zones(pf);
      write_velocity_profile(S, pf);
      summarise_drag(S, pf, summarise_fluxes(S));
    }

    /// The force of the material on a boundary with a velocity condition, as the reaction of the
    /// discrete momentum equation (25a) at its nodes: with v the sum of the shape functions of
    /// one component at the boundary's dofs (1 on the boundary, 0 at every other node),
    /// F . e = -(a(u, v) - <lambda, gamma(v)> - l(v)). This is the variationally consistent flux,
    /// which converges with the velocity; the trace lambda n of the P1d stress, whose vertex values
    /// oscillate, moved by 50 % under refinement of the cylinder channel.
    ///
    /// Where the boundary leaves a direction free and carries an External pressure, that pressure
    /// is added.
    ///
    /// A node's reaction r acts along the directions its conditions fix. Where several boundaries
    /// meet (a corner), each takes its share: with P_f the projection onto the directions that
    /// face f's condition fixes (I for No-slip, e e^T for a fixed component e or a constrained
    /// direction d) and w_f the integral of the node's shape function on f, boundary b gets
    /// W_b M^+ r, W_b = sum_{f in b} w_f P_f and M = sum_f w_f P_f. The shares add up to r; for
    /// fixed components this is each component's reaction split in proportion to w_f (when
    /// each boundary took the whole reaction, a split Bingham wall carried 0.517 on each half of
    /// 0.5).
    Tensor<1, dim>
    Problem::boundary_force(const types::boundary_id id) const
    {
      struct Node
      {
        types::global_dof_index y;
        SymmetricTensor<2, dim> on_id, on_all; // W_id, M
      };
      std::map<types::global_dof_index, Node> nodes; // by x-dof
      for_each_boundary_node([&](const types::boundary_id b, const Tensor<1, dim> &n,
                                 const types::global_dof_index x, const types::global_dof_index y,
                                 const double w) {
        SymmetricTensor<2, dim> P;
        for (const auto &vb : velocity_boundaries)
          if (vb.id == b)
            {
              for (unsigned int c = 0; c < dim; ++c)
                P[c][c] += vb.mask[c] ? 1. : 0.;
              if (vb.direction != VelocityBoundary::Direction::none)
                {
                  const Tensor<1, dim> d = VelocityBoundary::fixed_direction(vb.direction, n);
                  P += symmetrize(outer_product(d, d));
                }
            }
        if (P.norm() == 0.)
          return;
        Node &node = nodes[x];
        node.y     = y;
        node.on_all += w * P;
        if (b == id)
          node.on_id += w * P;
      });
      // (A u - l - H^T lambda)_i: zero to the solver's tolerance where i is free
      const auto reaction = [&](const types::global_dof_index i) {
        if (!reaction_dof[i])
          return 0.;
        double r = -load_all[i];
        if (const auto row = A_constrained.find(i); row != A_constrained.end())
          for (const auto &[j, a] : row->second)
            r += a * u[j];
        if (const auto column = H_constrained.find(i); column != H_constrained.end())
          for (const auto &[k, h] : column->second)
            r -= h * solution.lambda[k];
        return r;
      };
      Tensor<1, dim> force;
      for (const auto &[x, node] : nodes)
        {
          if (node.on_id.norm() == 0.)
            continue;
          // M^+ (M is singular where one direction is fixed)
          SymmetricTensor<2, dim> M_plus;
          const auto              modes = eigenvectors(node.on_all);
          for (const auto &[value, vector] : modes)
            if (value > 1e-6 * modes.front().first) // walls meeting within 1e-3 rad: straight
              M_plus += symmetrize(outer_product(vector, vector)) / value;
          const Tensor<1, dim> r({reaction(x), reaction(node.y)});
          force -= node.on_id * (M_plus * r);
        }
      // Along the directions the boundary leaves free there is no reaction, but an external
      // pressure may act (Zero tangential velocity, or Zero x-velocity on a face y = const): its
      // traction -p_ext n acts on the material, which pushes back with p_ext n.
      for (const auto &[pressed, p_ext] : external_pressures)
        if (pressed == id)
          {
            const QGauss<dim - 1> face_quadrature(1);
            FEFaceValues<dim>     fvf(mapping, fe_u, face_quadrature,
                                      update_normal_vectors | update_JxW_values);
            for_each_face_on(dof_u, id, fvf, [&](const auto &) {
              force += p_ext * fvf.normal_vector(0) * fvf.JxW(0);
            });
          }
      return force;
    }

    /// int_Gamma 2/Re eta D^b(u) n over boundary `id` (n the domain's outward normal), with
    /// D^b(u) = D0(u) + b/d div(u) I as in a(., .) (25a), and eta = 1 or, for the Bagnold
    /// viscosity, bagnold_viscosity().
    Tensor<1, dim>
    Problem::viscous_traction_force(const types::boundary_id id) const
    {
      const QGauss<dim - 1>                face_quadrature(4);
      FEFaceValues<dim>                    fvf(mapping, fe_u, face_quadrature,
                                               update_gradients | update_normal_vectors | update_JxW_values);
      const FEValuesExtractors::Vector     velocity(0);
      std::vector<SymmetricTensor<2, dim>> D(face_quadrature.size());
      const bool                           bagnold = prm.rheology.viscosity == "bagnold";
      Tensor<1, dim>                       force;
      for_each_face_on(dof_u, id, fvf, [&](const auto &) {
        fvf[velocity].get_function_symmetric_gradients(u, D);
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          {
            const double                  eta = bagnold ? bagnold_viscosity(D[q]) : 1.;
            const SymmetricTensor<2, dim> Db =
                deviator(D[q]) + prm.rheology.b / dim * trace(D[q]) * unit_symmetric_tensor<dim>();
            force += 2. / prm.rheology.Re * eta * (Db * fvf.normal_vector(q)) * fvf.JxW(q);
          }
      });
      return force;
    }

    void
    Problem::write_vtu()
    {
      DataOut<dim> data_out;
      data_out.attach_triangulation(mesh.triangulation);
      const std::vector<std::string> names(dim, "velocity");
      const std::vector<DataComponentInterpretation::DataComponentInterpretation> vector_part(
        dim, DataComponentInterpretation::component_is_part_of_vector);
      data_out.add_data_vector(dof_u, u, names, vector_part);
      data_out.add_data_vector(cell_zone, "zone", DataOut<dim>::type_cell_data);
      for (const auto &[name, field] : stress_fields)
        if (name.rfind("lambda_", 0) != 0)
          data_out.add_data_vector(dof_s, field, name);
      data_out.build_patches(mapping, 2);
      out.write_solution(data_out);
    }
  } // namespace

  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log)
  {
    Problem problem(parameters, output, log);
    return problem.run();
  }
} // namespace granflow::dp
