// The dp Problem's operators: A and l of (25a), the constraint operator B with the points' weights
// (4.3, Property 3), and the residual's scale at each point.
#include "models/dp/dp_problem.h"

#include <deal.II/dofs/dof_tools.h>

namespace granflow::dp::detail
{
  /// Daviet (25a): a(u, v) = 2/Re int eta (D0(u):D0(v) + b/d div u div v), l(v) = int e_g . v
  /// + int_{B_N} sigma_ext n . v. A is kept on the free dofs; the Dirichlet lifting moves to l.
  void
  Problem::assemble_velocity_operator(const std::vector<double> &eta)
  {
    const auto                           t0 = std::chrono::steady_clock::now();
    const double                         Re = prm.rheology.Re, b = prm.rheology.b;
    const Tensor<1, dim>                 e_g = prm.e_g();
    FEValues<dim>                        fv(mapping, fe_u, quadrature,
                                            update_values | update_gradients | update_JxW_values |
                                                update_quadrature_points);
    const FEValuesExtractors::Vector     velocity(0);
    const unsigned int                   n = fe_u.n_dofs_per_cell(), nq = quadrature.size();
    std::vector<types::global_dof_index> dofs(n);
    std::vector<std::map<int, double>>   rows(n_free);
    std::vector<double>                  load(dof_u.n_dofs(), 0.), lifting(n_free, 0.);
    std::vector<SymmetricTensor<2, dim>> eps(n);
    A_constrained.clear();
    std::vector<double> div(n);
    std::size_t         cell_index = 0;
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
    data.A = csr_from_rows(rows, n_free);
    data.l = std::move(lifting);
    for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
      if (free_index[i] >= 0)
        data.l[free_index[i]] += free_coefficient[i] * load[i];
    load_all = std::move(load); // body force and tractions, no lifting
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
    const Quadrature<dim>            rule = p1d ? constraint_rule() : Quadrature<dim>(quadrature);
    FEValues<dim>                    fv(mapping, fe_u, rule,
                                        update_gradients | update_JxW_values | update_quadrature_points);
    FEValues<dim>                    fv_s(mapping, fe_s, rule, update_values);
    const unsigned int               n = fe_u.n_dofs_per_cell(), ns = fe_s.n_dofs_per_cell();
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

    data.H          = csr_from_rows(rows, n_free); // n_points * s_d rows
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
} // namespace granflow::dp::detail
