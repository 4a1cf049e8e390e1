// The dp Problem's postprocessing and output: fields at the constraint points and zones, the
// velocity profile, fluxes, boundary forces and drag (6.3.1), the summary and the VTU.
#include "models/dp/dp_problem.h"

#include "core/format_number.h"
#include "core/max_abs.h"
#include "postprocess/analytic.h"

#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/data_out.h>

#include <limits>
#include <sstream>
#include <tuple>

namespace granflow::dp::detail
{
  /// Fields at the constraint points (stress lambda; discrete strain rate gamma / (2 w_i), the
  /// chi-coordinates of D(u) the rheology sees) and the zones; sets stress_fields and cell_zone.
  Problem::PointFields
  Problem::point_fields()
  {
    const double         sqrt_2_over_d = std::sqrt(2. / dim); // p = sqrt(2/d) lambda_N (Property 2)
    PointFields          pf;
    std::vector<double> &p = pf.p, &div_u = pf.div_u, &D0_norm = pf.D0_norm, &zone = pf.zone;
    for (std::vector<double> *v : {&p, &div_u, &D0_norm, &zone})
      v->resize(n_points);
    std::vector<double> tau_xx(n_points), tau_xy(n_points), lambda_N(n_points), lambda_1(n_points),
        lambda_2(n_points), D0_1(n_points), D0_2(n_points), residual(n_points);
    double &max_D0 = pf.max_D0, &max_div = pf.max_div;
    for (std::size_t i = 0; i < n_points; ++i)
      {
        const double *l = &solution.lambda[i * s_d], *g = &solution.gamma[i * s_d];
        const double  w = 2. * point_weight[i];
        lambda_N[i]     = l[0];
        lambda_1[i]     = l[1];
        lambda_2[i]     = l[2];
        p[i]            = sqrt_2_over_d * l[0];
        tau_xx[i]       = -l[1]; // tau = -Dev(lambda), chi(0; b, c) = [[b, c], [c, -b]]
        tau_xy[i]       = -l[2];
        D0_1[i]         = g[1] / w;
        D0_2[i]         = g[2] / w;
        D0_norm[i]      = std::hypot(D0_1[i], D0_2[i]);
        div_u[i]        = std::sqrt(2. * dim) * g[0] / w;
        max_D0          = std::max(max_D0, D0_norm[i]);
        // Where the solver's residual is largest (the rheology is violated by this much).
        const double    c = data.gamma_scale[i];
        const SymVector lv{{l[0], l[1], l[2]}}, gv{{c * g[0], c * g[1], c * g[2]}};
        residual[i] = rheology::norm(prm.solver.residual == "alart-curnier" || prm.rheology.Bi > 0.
                                         ? rheology::f_AC(lv, gv, prm.rheology.mu, prm.rheology.Bi)
                                         : rheology::f_FB(lv, gv, prm.rheology.mu));
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
          const std::array<double, 3> at_points{{values[base], values[base + 1], values[base + 2]}};
          const std::array<double, 3> v = linear ? vertex_values_from_points(at_points) : at_points;
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
    // one (a closed silo's floor carries 55.3 with the interior point, 57.5 with the fixed
    // point, of a weight of 64.5: docs/dp.md).
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
            << prm.solver.tolerance << " (lower it: docs/dp.md#fields-of-solution-0000vtu); ";
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
          << "; lower the tolerance for a zone map (docs/dp.md#fields-of-solution-0000vtu)";
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
    const auto [a, b] = *profile;
    S["profile_line"] = {{"start", {a[0], a[1]}}, {"end", {b[0], b[1]}}};
    const auto samples =
        postprocess::sample_line(mapping, dof_u, u, a, b, prm.output.profile_points);
    // First column: the coordinate that varies along the line (y for a vertical line).
    const unsigned int  axis = std::abs(b[1] - a[1]) >= std::abs(b[0] - a[0]) ? 1 : 0;
    std::vector<double> coord, ux, uy, shear;
    for (std::size_t k = 0; k < samples.points.size(); ++k)
      {
        coord.push_back(samples.points[k][axis]);
        ux.push_back(samples.values[k][0]);
        uy.push_back(samples.values[k][1]);
        shear.push_back(samples.gradients[k][0][1]); // du_x/dy
      }
    std::vector<std::string>         header  = {axis ? "y" : "x", "u_x", "u_y", "du_x/dy"};
    std::vector<std::vector<double>> columns = {coord, ux, uy, shear};

    const std::string &reference = prm.output.reference;
    if (reference != "none")
      {
        std::vector<double> u_ref, shear_ref;
        const double        Bi = prm.rheology.Bi, Re = prm.rheology.Re, mu = prm.rheology.mu;
        const double        alpha = std::atan2(prm.e_g()[0], -prm.e_g()[1]);
        // Both references are profiles across the layer, functions of y alone: evaluated at each
        // sample's y, whichever way the line runs (a horizontal line's coord is its x).
        for (const auto &point : samples.points)
          if (const double y = point[1]; reference == "bingham poiseuille")
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
            max_err       = max_abs(max_err, ux[k] - u_ref[k]);
            max_ref       = max_abs(max_ref, u_ref[k]);
            max_shear_err = max_abs(max_shear_err, shear[k] - shear_ref[k]);
            max_shear_ref = max_abs(max_shear_ref, shear_ref[k]);
          }
        header.insert(header.end(), {"u_x_reference", "du_x/dy_reference"});
        columns.push_back(u_ref);
        columns.push_back(shear_ref);
        S["reference"]   = reference;
        const double nan = std::numeric_limits<double>::quiet_NaN();
        // relative to the reference's largest value on the line; null where it is 0 there (a
        // line along a no-slip wall, the shear rate across a plug)
        const double rel_error   = max_ref > 0. ? max_err / max_ref : nan;
        S["max_rel_error"]       = rel_error;
        S["max_rel_error_shear"] = max_shear_ref > 0. ? max_shear_err / max_shear_ref : nan;
        for (const auto &[what, largest, error] : {std::tuple{"velocity", max_ref, max_err},
                                                   {"shear rate", max_shear_ref, max_shear_err}})
          if (!(largest > 0.))
            {
              std::ostringstream w;
              w << std::setprecision(3) << "the reference " << what
                << (std::isnan(largest) ? " is not a number on the profile line (is the line "
                                          "outside the layer the reference describes?)"
                                        : " is 0 all along the profile line")
                << ", so its relative error is not defined (null in max_rel_error"
                << (std::string(what) == "velocity" ? "" : "_shear")
                << "); the largest difference is " << error;
              report.warn(w.str());
            }
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
            double      plug_gamma_T = 0., plug_D0 = 0.;
            std::size_t plug_points = 0;
            for (std::size_t i = 0; i < n_points; ++i)
              if (std::abs(point_location[i][1]) < Bi - 2. * h)
                {
                  plug_gamma_T = std::max(
                      plug_gamma_T, data.gamma_scale[i] * std::hypot(solution.gamma[i * s_d + 1],
                                                                     solution.gamma[i * s_d + 2]));
                  plug_D0 = std::max(plug_D0, D0_norm[i]);
                  ++plug_points;
                }
            // Daviet Fig. 5: errors over the whole domain against the analytic profile, in the
            // max norm and the H1 seminorm (at the points of a degree-6 rule).
            QGaussSimplex<dim>                       q_err(4);
            FEValues<dim>                            fv(mapping, fe_u, q_err,
                                                        update_values | update_gradients | update_quadrature_points |
                                                            update_JxW_values);
            std::vector<Vector<double>>              uq(q_err.size(), Vector<double>(dim));
            std::vector<std::vector<Tensor<1, dim>>> gq(q_err.size(),
                                                        std::vector<Tensor<1, dim>>(dim));
            double                                   error_Linf = 0., error_H1_sq = 0.;
            for (const auto &cell : dof_u.active_cell_iterators())
              {
                fv.reinit(cell);
                fv.get_function_values(u, uq);
                fv.get_function_gradients(u, gq);
                for (unsigned int q = 0; q < q_err.size(); ++q)
                  {
                    const double y    = fv.quadrature_point(q)[1];
                    const double e    = analytic::bingham_poiseuille_velocity(y, Bi, Re) - uq[q][0];
                    error_Linf        = max_abs(max_abs(error_Linf, e), uq[q][1]);
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
                w << std::setprecision(3) << "the sheared layer by each wall, 1 - Bi = " << 1. - Bi
                  << ", spans " << (1. - Bi) / h << " elements (longest edge h = " << h
                  << "): the mesh does not resolve it, and max_rel_error is ";
                if (std::isnan(rel_error))
                  w << "not defined";
                else
                  w << rel_error;
                w << "; refine (Geometry/Mesh size or Global refinements)";
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
  Problem::summarise_inflow(nlohmann::json                                                &S,
                            const std::map<types::boundary_id, postprocess::BoundaryFlux> &flux_of)
  {
    Inflow result;
    if (prm.output.inflow_boundary.empty())
      return result;
    // Below jammed_speed the channel is jammed: 1e-5 Re sqrt(g L) (velocities scale with Re,
    // (23)); at the sweep's Re = 100 that is 1e-3, as in scripts/cylinder_drag_sweep.sh (its
    // jammed channels creep at the solver's accuracy in u, its slowest flowing one has 0.43).
    const double jammed_speed = 1e-5 * prm.rheology.Re;
    const auto  &inflow       = flux_of.at(mesh.id(prm.output.inflow_boundary, prm.case_file));
    result.U_inf              = -inflow.flux / inflow.length;
    result.u_x                = inflow.mean_u_x;
    S["U_infinity"]           = result.U_inf;
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
            log.print("dp: note: the flow is jammed (U_infinity = " + format_number(inflow.U_inf) +
                      "): drag_coefficient is null\n");
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
    S["upstream_pressure_peak"] = {
        {"x", measured(!centreline.empty(), along * peak_x)},
        {"mean_pressure", measured(!centreline.empty(), peak_p)},
        {"distance_from_cylinder_over_D", measured(!centreline.empty(), (-peak_x - R) / (2. * R))}};
  }

  /// Fields at the constraint points, the zones, profiles, fluxes, drag and errors against the
  /// analytic reference: summary.json, profiles/ and the stress-space fields of the VTU.
  void
  Problem::postprocess(Results &results)
  {
    const PointFields pf          = point_fields();
    nlohmann::json   &S           = results.summary;
    S["traction_free_boundaries"] = traction_free;
    S["case"]                     = prm.name;
    S["case_file"]                = prm.case_file;
    S["model"]                    = "dp";
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
} // namespace granflow::dp::detail
