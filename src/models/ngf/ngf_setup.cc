// ngf: the mesh of each geometry, the dofs, the Jacobian's pattern and the constraints
// (periodicity, the rotated periodicity of the slice, the Dirichlet conditions (28), (25)).
#include "models/ngf/ngf_problem.h"

#include "core/errors.h"
#include "core/interrupt.h"
#include "fem/mapping_without_cell_similarity.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

namespace granflow::ngf::detail
{
  namespace
  {
    solvers::NewtonOptions
    newton_options(const SolverParameters &s, Logger &log)
    {
      solvers::NewtonOptions o;
      o.tolerance           = s.tolerance;
      o.max_iterations      = s.max_iterations;
      o.reuse_factorization = s.reuse_factorization;
      o.log                 = &log.table();
      o.stop_requested      = interrupt::requested; // a Ctrl-C ends an increment's iterations
      return o;
    }
  } // namespace

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
        column ? std::map<std::string, types::boundary_id>{{"wall", wall_id}, {"bottom", outer_id}}
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
          GridGenerator::subdivided_hyper_rectangle(tria, {scale.n_2, scale.n_2, scale.n_1},
                                                    Point<3>(0., 0., 0.),
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
                  face->set_boundary_id(id == 2 ? 4 : id == 3 ? 5 : id == 4 ? 2 : id == 5 ? 3 : id);
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
    if (sparsity.n_nonzero_elements() >= static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw InputError(prm.case_file, "Geometry/Element size",
                       "the mesh's Jacobian has " + std::to_string(sparsity.n_nonzero_elements()) +
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
        std::vector<GridTools::PeriodicFacePair<typename DoFHandler<dim>::cell_iterator>> periodic;
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
    for (const auto i : DoFTools::extract_boundary_dofs(dof_handler, ComponentMask(), {first_face}))
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

  // Each member defined here is instantiated here, for both element types (ngf_problem.h).
#define GRANFLOW_NGF_INSTANTIATE(D)                                                                \
  template Problem<D>::Problem(const Parameters &prm, OutputDirectory &out, Logger &log);          \
  template types::boundary_id Problem<D>::boundary_id(const std::string &name) const;              \
  template void               Problem<D>::make_mesh();                                             \
  template void               Problem<D>::index_jacobian_csr();                                    \
  template void               Problem<D>::setup_system();                                          \
  template void Problem<D>::make_constraints(AffineConstraints<double> &c, const double u_wall,    \
                                             const bool homogeneous) const;                        \
  template void Problem<D>::add_rotated_periodicity(AffineConstraints<double> &c) const;

  GRANFLOW_NGF_INSTANTIATE(2)
  GRANFLOW_NGF_INSTANTIATE(3)
#undef GRANFLOW_NGF_INSTANTIATE
} // namespace granflow::ngf::detail
