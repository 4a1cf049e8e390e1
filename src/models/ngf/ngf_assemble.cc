// ngf: the coupled residual (32)-(35) and its consistent Jacobian (Henann & Kamrin 2016, Section
// 5), the boundary loads, the linear solve and one increment's Newton iterations.
#include "models/ngf/ngf_problem.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/work_stream.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

namespace granflow::ngf::detail
{
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
          copy.force_scale    = std::max(copy.force_scale,
                                         std::sqrt(eo.magnitude[4 * a] * eo.magnitude[4 * a] +
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
    WorkStream::run(dof_handler.begin_active(), dof_handler.end(), worker, copier, sample, Copy());

    // Henann 6.1: L_inf norms of the assembled residuals, each normalised by an element-level
    // nodal contribution to it. The paper takes the average; here it is the largest magnitude of
    // the terms that make up an element's nodal residual: where the flow is confined to a few
    // elements (its onset near a free surface) the average over the mesh is mostly zeros and
    // would demand more than round-off allows.
    ResidualNorms n = residual_norms();
    if (std::isnan(n.u))
      return n;
    n.u_scale                = force_scale;
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
  solvers::NewtonStats
  Problem<dim>::newton(const double dt, const unsigned int increment)
  {
    Increment                  step(*this, dt);
    const solvers::NewtonStats stats = newton_solver.solve(step, increment);
    for (unsigned int k = 0; k < stats.history.size(); ++k)
      {
        const auto &it = stats.history[k];
        newton_log.push_back(
            {increment, k, it.residual[0], it.residual[1], it.correction[0], it.correction[1]});
      }
    return stats;
  }

  // Each member defined here is instantiated here, for both element types (ngf_problem.h).
#define GRANFLOW_NGF_INSTANTIATE(D)                                                                \
  template bool Problem<D>::solve_with_jacobian(Vector<double> &dU, const bool factorize);         \
  template void Problem<D>::add_boundary_loads(                                                    \
      const typename DoFHandler<D>::active_cell_iterator &cell, FEFaceValues<D> &face,             \
      Vector<double> &r_local) const;                                                              \
  template Problem<D>::ResidualNorms Problem<D>::residual_norms() const;                           \
  template Problem<D>::ResidualNorms Problem<D>::assemble(const double dt,                         \
                                                          const bool   with_jacobian);               \
  template solvers::NewtonStats Problem<D>::newton(const double dt, const unsigned int increment);

  GRANFLOW_NGF_INSTANTIATE(2)
  GRANFLOW_NGF_INSTANTIATE(3)
#undef GRANFLOW_NGF_INSTANTIATE
} // namespace granflow::ngf::detail
