// ngf: postprocessing (Henann & Kamrin 2016, Section 6): the profile across the band and W, the
// finite-difference reference of (90) / (92), the wall pressure, mu_wall's rate-dependent part,
// profiles at depth, the histories and the VTU.
#include "models/ngf/ngf_problem.h"

#include "core/errors.h"
#include "core/max_abs.h"
#include "postprocess/nonlocal_1d.h"

#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

namespace granflow::ngf::detail
{
  namespace
  {
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
  } // namespace

  /// history.csv (per increment) and newton.csv (per Newton iterate).
  template <int dim>
  void
  Problem<dim>::write_histories(const std::vector<double> &wall_displacement,
                                const std::vector<double> &mu_wall,
                                const std::vector<double> &newton_iterations)
  {
    // attempt: 0 for an increment's first try, k after its k-th cut (march() takes a cut
    // increment again under the same number); the last attempt of each increment converged,
    // but for a run's final failure.
    std::vector<double> inc, it, ru, rg, cu, cg, attempt;
    for (const auto &r : newton_log)
      {
        const bool retake = r.iteration == 0 && !inc.empty() && inc.back() == r.increment;
        attempt.push_back(inc.empty() || inc.back() != r.increment ? 0.
                          : retake                                 ? attempt.back() + 1.
                                                                   : attempt.back());
        inc.push_back(r.increment);
        it.push_back(r.iteration);
        ru.push_back(r.R_u);
        rg.push_back(r.R_g);
        cu.push_back(r.dU_u);
        cg.push_back(r.dU_g);
      }
    out.write_csv("history.csv", {"wall_displacement_over_d", "mu_wall", "newton_iterations"},
                  {wall_displacement, mu_wall, newton_iterations});
    out.write_csv(
        "newton.csv",
        {"increment", "iteration", "R_u", "R_g", "correction_u", "correction_g", "attempt"},
        {inc, it, ru, rg, cu, cg, attempt});
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
        const WallProfile p    = profile_at_depth(v, depth);
        const std::string file = "profiles/velocity_at_depth_" + profile_depth_name(depth) + ".csv";
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
  Problem<dim>::judge_band(nlohmann::json &summary, const WallProfile &profile, const bool finished)
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
        worst = max_abs(worst, vfd - profile.v[i]);
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
    // The column's mu_wall is the wall node's reaction over P_wall, and that reaction averages
    // the shear stress over the first element, where the pressure is P_wall plus up to the
    // weight of the element's layer: about mu (1 + phi rho_s G h / (2 P_wall)) P_wall. Where
    // that weight is not small against P_wall, mu_wall is the mesh's (at P_wall / (phi rho_s G
    // d) = 1e-3 and h = d/3: 75, against about 0.4 on fine meshes).
    const double half_weight = column ? scale.body_force * scale.h / 2. : 0.;
    if (finished && half_weight > 0.1 * scale.P_wall)
      {
        std::ostringstream w;
        w << std::setprecision(3) << "the weight of half an element's layer, phi rho_s G h / 2, is "
          << half_weight / scale.P_wall
          << " P_wall: the wall's reaction averages the shear stress over the first element, "
             "where the pressure is up to that much above P_wall, so mu_wall (and the wall's "
             "pressure, "
          << p_wall
          << " P_wall) carry an error of that order; raise Loading/Wall pressure or refine "
             "Geometry/Element size";
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
    out.write_csv("profiles/stress.csv",
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

  // Each member defined here is instantiated here, for both element types (ngf_problem.h).
#define GRANFLOW_NGF_INSTANTIATE(D)                                                                                 \
  template void Problem<D>::write_histories(const std::vector<double> &wall_displacement,                           \
                                            const std::vector<double> &mu_wall,                                     \
                                            const std::vector<double> &newton_iterations);                          \
  template void Problem<D>::compute_reference();                                                                    \
  template Problem<D>::WallProfile Problem<D>::wall_profile(const Vector<double> &v,                                \
                                                            const double          level) const;                              \
  template Problem<D>::WallProfile Problem<D>::profile_at_depth(const Vector<double> &v,                            \
                                                                const double          depth) const;                          \
  template void                    Problem<D>::write_profiles_at_depths(                                            \
                         nlohmann::json &summary, const Vector<double> &v, const std::vector<std::string> &header); \
  template double Problem<D>::g_unit() const;                                                                       \
  template double Problem<D>::judge_band(nlohmann::json &summary, const WallProfile &profile,                       \
                                         const bool finished);                                                      \
  template std::vector<double> Problem<D>::compare_with_reference(                                                  \
      nlohmann::json &summary, const WallProfile &profile, const double W) const;                                   \
  template void Problem<D>::report_wall_pressure(                                                                   \
      nlohmann::json &summary, const std::vector<double> &xc, const std::vector<double> &p,                         \
      const bool finished);                                                                                         \
  template void Problem<D>::postprocess(nlohmann::json &summary, const Vector<double> &v,                           \
                                        const bool finished);                                                       \
  template void Problem<D>::report_wall_pressure_with_gravity(                                                      \
      nlohmann::json &summary, const std::vector<double> &xc, const std::vector<double> &p_column,                  \
      const bool finished);                                                                                         \
  template void Problem<D>::compare_rate_dependent_part(nlohmann::json &summary,                                    \
                                                        const double    mu_wall) const;                                \
  template void Problem<D>::write_vtu(const Vector<double> &v);

  GRANFLOW_NGF_INSTANTIATE(2)
  GRANFLOW_NGF_INSTANTIATE(3)
#undef GRANFLOW_NGF_INSTANTIATE
} // namespace granflow::ngf::detail
