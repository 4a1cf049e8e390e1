#include "models/ngf/ngf_parameters.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace granflow::ngf
{
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;
  using granflow::Interval;
  using Anything = dealii::Patterns::Anything;

  void
  Parameters::declare(dealii::ParameterHandler &prm)
  {
    prm.add_parameter("Model", model, "Model of this case file: ngf (Henann & Kamrin 2016).",
                      Selection("ngf"));
    prm.add_parameter("Name", name,
                      "Name of the case, used in summary.json (empty: the case file's name "
                      "without .prm).",
                      Anything());

    prm.enter_subsection("Material");
    {
      auto &m = material;
      prm.add_parameter("mu_s", m.nonlocal.mu_s, "Static yield stress ratio mu_s (22), in (0, 1).",
                        Interval(0., true, 1., true));
      prm.add_parameter("b", m.nonlocal.b, "Rate sensitivity b of mu_loc = mu_s + b I (1), > 0.",
                        Interval::positive());
      prm.add_parameter("A", m.nonlocal.A,
                        "Nonlocal amplitude A of xi = A d / sqrt|mu - mu_s| (24), > 0.",
                        Interval::positive());
      prm.add_parameter("Grain diameter", m.nonlocal.d, "Mean grain diameter d [m], > 0.",
                        Interval::positive());
      prm.add_parameter("Grain density", m.nonlocal.rho_s,
                        "Grain material density rho_s [kg/m^3], > 0.", Interval::positive());
      prm.add_parameter("Shear modulus", m.elastic.S, "Shear modulus S of (12) [Pa], > 0.",
                        Interval::positive());
      prm.add_parameter("Bulk modulus", m.elastic.B, "Bulk modulus B of (12) [Pa], > 0.",
                        Interval::positive());
      prm.add_parameter("Solid fraction", m.phi,
                        "Solid volume fraction phi of b_0 = phi rho_s G (27), in (0, 1].",
                        Interval(0., true, 1., false));
      prm.add_parameter("Gravity", m.G, "Acceleration of gravity G [m/s^2], > 0.",
                        Interval::positive());
      prm.add_parameter("Cooperativity length cap", m.nonlocal.xi_cap_over_d,
                        "Smooth cap of xi in grain diameters (Section 4 footnote: 1000), > 0.",
                        Interval::positive());
    }
    prm.leave_subsection();

    prm.enter_subsection("Geometry");
    {
      auto &g = geometry;
      prm.add_parameter(
          "Shape", g.shape,
          "shear column: one column of 8-node bricks, depth along z, periodic in x and y, "
          "driven wall at z = 0 ('wall'), fixed bottom ('bottom') (Henann 6.1, Fig. 1a); "
          "annulus row: one row of generalized-axisymmetric quads from R_i ('inner wall', "
          "rotated) to R_o ('outer wall', pressed), u_z = 0 (6.2, Fig. 3a); annulus: the "
          "(R, Z) section of an annular cell of height H with gravity, smooth floor ('bottom'), "
          "free surface ('top') (6.3, Fig. 5a); annulus slice: the same cell as a 3D slice of "
          "bricks one element thick with rotated periodic faces (6.3).",
          Selection("shear column|annulus row|annulus|annulus slice"));
      prm.add_parameter("Depth", g.depth,
                        "Bed depth of the shear column in grain diameters (6.1: 20), > 0.",
                        Interval::positive());
      prm.add_parameter("Inner radius", g.inner_radius,
                        "Annulus inner radius R_i in grain diameters (6.2: 20 to 100), in [1, "
                        "1e5]: a continuum wall of less than a grain's radius is not a model of "
                        "the paper's cell.",
                        Interval(1., false, 1e5, false));
      prm.add_parameter("Gap", g.gap, "Annulus width R_o - R_i in grain diameters (6.2: 20), > 0.",
                        Interval::positive());
      prm.add_parameter("Height", g.height,
                        "Annulus fill height H in grain diameters (6.3: 15), > 0.",
                        Interval::positive());
      prm.add_parameter("Slice angle", g.slice_angle,
                        "Angle of the 3D annulus slice in degrees (6.3: 0.1), in (0, 10].",
                        Interval::positive(10.));
      prm.add_parameter(
          "Element size", g.element_size,
          "Element size h in grain diameters (6.1: 1/3); rounded so that every length is an "
          "integer number of elements, > 0, and at most 1e6 elements in all.",
          Interval::positive());
    }
    prm.leave_subsection();

    prm.enter_subsection("Loading");
    {
      auto &l = loading;
      prm.add_parameter(
          "Wall pressure", l.wall_pressure,
          "Shear column: dimensionless wall pressure P_wall / (phi rho_s G d) (6.1), > 0.",
          Interval::positive());
      prm.add_parameter("Confining pressure", l.confining_pressure,
                        "Annulus row: pressure P_wall on the outer wall [Pa] (6.2), > 0.",
                        Interval::positive());
      prm.add_parameter(
          "Wall speed", l.wall_speed,
          "Dimensionless speed of the driven wall: v_wall / sqrt(G d) (shear column, 6.1), "
          "R_i Omega sqrt(rho_s / P_wall) (annulus row, 6.2), R_i Omega / sqrt(G d) (annulus, "
          "6.3); > 0.",
          Interval::positive());
      prm.add_parameter("Wall displacement", l.wall_displacement,
                        "Shear column: wall displacement at the end of the run, in grain diameters "
                        "(6.1: 1), in (0, 1e4].",
                        Interval::positive(1e4));
      prm.add_parameter("Wall rotation", l.wall_rotation,
                        "Annulus: rotation of the inner wall at the end of the run [degrees] (6.2, "
                        "6.3: 4), in (0, 3600].",
                        Interval::positive(3600.));
    }
    prm.leave_subsection();

    prm.enter_subsection("Fluidity boundary conditions");
    {
      prm.add_parameter("Dirichlet", fluidity_bc.dirichlet,
                        "'name: g_wall, ...': prescribed fluidity [1/s], >= 0, on these boundaries "
                        "(25); a boundary is named at most once in this list and the Neumann one.",
                        Anything());
      prm.add_parameter(
          "Neumann", fluidity_bc.neumann,
          "'name: zeta, ...': prescribed grad g . n [1/(s m)], n the outward normal (25); every "
          "other boundary has zeta = 0.",
          Anything());
    }
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    {
      auto &s = solver;
      prm.add_parameter(
          "Fluidity", s.fluidity,
          "nonlocal: g is a nodal unknown solving (23); local: g = g_loc, the local rheology (1) "
          "(the comparison of Henann 6.3, Fig. 7).",
          Selection("nonlocal|local"));
      prm.add_parameter(
          "Tolerance", s.tolerance,
          "Newton stops when both normalised residuals R_u, R_g (Section 6.1) are below, in (0, "
          "1e-3]; or, at their round-off floor, when the full Newton correction is below 1e-10 "
          "of each field (its largest value).",
          Interval::positive(1e-3));
      prm.add_parameter("Max Newton iterations", s.max_iterations,
                        "Newton iterations before the increment is cut, in [1, 100].",
                        Integer(1, 100));
      prm.add_parameter("First increment", s.first_increment,
                        "Wall displacement of the first shear increment, in grain diameters, > 0 "
                        "and at most Max increment.",
                        Interval::positive());
      prm.add_parameter("Max increment", s.max_increment,
                        "Largest wall displacement per increment, in grain diameters, > 0.",
                        Interval::positive());
      prm.add_parameter(
          "Reuse factorization", s.reuse_factorization,
          "Take Newton steps with the last factorized Jacobian (also across increments) while "
          "each reduces the residual at least 4 times; false: a fresh Jacobian every iteration "
          "(pure Newton, as for the quadratic-convergence study of Fig. 2c).",
          Bool());
      prm.add_parameter(
          "Increment growth", s.growth,
          "Factor by which the increment grows after a solve in at most 4 iterations, >= 1.",
          Double(1.));
    }
    prm.leave_subsection();

    prm.enter_subsection("Output");
    {
      prm.add_parameter(
          "Reference", output.reference,
          "none, or finite difference: the 1D reduction (90) (shear column) or (92) (annulus "
          "row) solved on a 0.01 d grid at the same wall speed, written beside the profile and "
          "compared in summary.json; for the nonlocal model with zeta = 0 on every boundary, as "
          "the reductions have.",
          Selection("none|finite difference"));
      prm.add_parameter("Write vtu", output.write_vtu, "Write solution-0000.vtu and solution.pvd.",
                        Bool());
      prm.add_parameter(
          "Profile depths", output.profile_depths,
          "Annulus with gravity (quad section or slice): 'depth, ...' in grain diameters below the "
          "free surface, each in [0, Geometry/Height]; for each, "
          "profiles/velocity_at_depth_DEPTH.csv holds the radial profile at that depth (as "
          "profiles/velocity.csv does at the surface) and summary.json its W/d. Empty: none.",
          Anything());
    }
    prm.leave_subsection();
  }

  void
  Parameters::validate() const
  {
    const std::string &f = case_file;
    {
      // Elements along and across the shear gradient, as scales() rounds them (before rounding, so
      // that an absurd ratio cannot overflow the count).
      const double along = (geometry.shape == "shear column" ? geometry.depth : geometry.gap) /
                           geometry.element_size,
                   across = geometry.shape == "annulus" || geometry.shape == "annulus slice"
                                ? geometry.height / geometry.element_size
                                : 1.;
      constexpr double max_elements = 1e6;
      if (!(along * across <= max_elements))
        {
          std::ostringstream s;
          s << "= " << geometry.element_size << " gives about " << std::setprecision(3)
            << along * across << " elements on the " << geometry.shape
            << ": expected at most 1e6 (a larger element size, or a smaller domain)";
          throw InputError(f, "Geometry/Element size", s.str());
        }
    }
    // An entry that the shape does not use would be ignored without a word (a user varying the
    // annulus row's "Wall pressure" got identical runs): it must keep its default.
    {
      const Parameters defaults;
      const bool column = geometry.shape == "shear column", row = geometry.shape == "annulus row",
                 slice = geometry.shape == "annulus slice", annulus = !column,
                 gravity_annulus = geometry.shape == "annulus" || slice;
      const struct
      {
        const char *entry;
        double      value, default_value;
        bool        used;
        const char *instead;
      } entries[] = {
          {"Geometry/Depth", geometry.depth, defaults.geometry.depth, column, "Geometry/Gap"},
          {"Geometry/Inner radius", geometry.inner_radius, defaults.geometry.inner_radius, annulus,
           "Geometry/Depth"},
          {"Geometry/Gap", geometry.gap, defaults.geometry.gap, annulus, "Geometry/Depth"},
          {"Geometry/Height", geometry.height, defaults.geometry.height, gravity_annulus, nullptr},
          {"Geometry/Slice angle", geometry.slice_angle, defaults.geometry.slice_angle, slice,
           nullptr},
          {"Loading/Wall pressure", loading.wall_pressure, defaults.loading.wall_pressure, column,
           row ? "Loading/Confining pressure" : nullptr},
          {"Loading/Confining pressure", loading.confining_pressure,
           defaults.loading.confining_pressure, row, column ? "Loading/Wall pressure" : nullptr},
          {"Loading/Wall displacement", loading.wall_displacement,
           defaults.loading.wall_displacement, column, "Loading/Wall rotation"},
          {"Loading/Wall rotation", loading.wall_rotation, defaults.loading.wall_rotation, annulus,
           "Loading/Wall displacement"},
          // The annulus row of 6.2 has no gravity, so b_0 = phi rho_s G (27) does not enter it.
          {"Material/Gravity", material.G, defaults.material.G, !row, nullptr},
          {"Material/Solid fraction", material.phi, defaults.material.phi, !row, nullptr}};
      for (const auto &e : entries)
        if (!e.used && e.value != e.default_value)
          {
            std::ostringstream s;
            s << "= " << e.value << " does not apply to Geometry/Shape = " << geometry.shape
              << ", which would ignore it: expected the default " << e.default_value;
            if (e.instead)
              s << " (the " << geometry.shape << "'s entry is " << e.instead << ")";
            else if (gravity_annulus && std::string(e.entry).find("pressure") != std::string::npos)
              s << " (the annulus's pressure comes from gravity and Geometry/Height)";
            else if (row)
              s << " (the annulus row of 6.2 has no gravity: its pressure is "
                   "Loading/Confining pressure)";
            throw InputError(f, e.entry, s.str());
          }
    }
    const bool column = geometry.shape == "shear column";
    const bool by_gap =
        !column && (geometry.shape == "annulus row" || geometry.gap <= geometry.height);
    const double shortest = column ? geometry.depth : by_gap ? geometry.gap : geometry.height;
    if (geometry.element_size > shortest)
      {
        std::ostringstream s;
        s << "= " << geometry.element_size << " is larger than the domain: expected at most "
          << (column   ? "Geometry/Depth"
              : by_gap ? "Geometry/Gap"
                       : "Geometry/Height")
          << " = " << shortest << " grain diameters";
        throw InputError(f, "Geometry/Element size", s.str());
      }
    if (solver.first_increment > solver.max_increment)
      {
        std::ostringstream s;
        s << "= " << solver.first_increment
          << ": expected at most Solver/Max increment = " << solver.max_increment;
        throw InputError(f, "Solver/First increment", s.str());
      }
    if (output.reference == "finite difference" &&
        (geometry.shape == "annulus" || geometry.shape == "annulus slice"))
      throw InputError(
          f, "Output/Reference",
          "'finite difference' has no 1D reduction for the annulus with gravity: expected none");
    if (solver.fluidity == "local" &&
        !(fluidity_bc.dirichlet.empty() && fluidity_bc.neumann.empty()))
      throw InputError(
          f, "Solver/Fluidity",
          "= local has no fluidity field: leave the Fluidity boundary conditions empty");
    // Fluidity boundaries (25): each names a boundary of the geometry, at most once in the two
    // lists together; a Dirichlet value is a fluidity g_wall >= 0.
    const auto               names     = boundary_names();
    const auto               dirichlet = fluidity_dirichlet(), neumann = fluidity_neumann();
    std::vector<std::string> named;
    for (const auto &[entry, list] :
         {std::pair{"Fluidity boundary conditions/Dirichlet", &dirichlet},
          std::pair{"Fluidity boundary conditions/Neumann", &neumann}})
      for (const auto &[name, value] : *list)
        {
          if (std::find(names.begin(), names.end(), name) == names.end())
            {
              std::string expected;
              for (const auto &n : names)
                expected += (expected.empty() ? "" : " or ") + n;
              throw InputError(f, entry,
                               "names boundary '" + name + "', which the " + geometry.shape +
                                   " lacks: expected " + expected);
            }
          if (std::find(named.begin(), named.end(), name) != named.end())
            throw InputError(f, entry,
                             "names boundary '" + name +
                                 "' a second time: expected each boundary at most once in the "
                                 "Dirichlet and Neumann lists together");
          named.push_back(name);
          // (parse_named_values has already rejected non-finite values)
          if (list == &dirichlet && value < 0.)
            {
              std::ostringstream s;
              s << "value " << value << " on '" << name << "': expected a number >= 0 (a fluidity)";
              throw InputError(f, entry, s.str());
            }
        }
    if (output.reference == "finite difference" &&
        (solver.fluidity == "local" || !dirichlet.empty() ||
         std::any_of(neumann.begin(), neumann.end(),
                     [](const auto &item) { return item.second != 0.; })))
      throw InputError(
          f, "Output/Reference",
          "'finite difference' is the 1D reduction of the nonlocal model with zeta = "
          "0 at both walls, which this case is not (Solver/Fluidity = local, or "
          "fluidity boundary conditions): expected none (--set Output/Reference=none)");
    profile_depths(); // throws on a bad list
  }

  std::vector<std::string>
  Parameters::boundary_names() const
  {
    if (geometry.shape == "shear column")
      return {"wall", "bottom"}; // z = 0 and z = depth
    // The annulus row's top and bottom are the planes u_z = 0 of a row one element high, which
    // stands for an infinitely tall annulus (6.2): grad g . n = 0 there is part of the reduction
    // to (92), not a condition to choose.
    if (geometry.shape == "annulus row")
      return {"inner wall", "outer wall"};
    return {"inner wall", "outer wall", "bottom", "top"};
  }

  Scales
  Parameters::scales() const
  {
    const auto  &m        = material;
    const double d        = m.nonlocal.d;
    auto         elements = [&](double length) {
      return static_cast<unsigned int>(std::max(1., std::round(length / geometry.element_size)));
    };
    Scales s{};
    s.d          = d;
    s.body_force = m.phi * m.nonlocal.rho_s * m.G;
    if (geometry.shape == "shear column")
      {
        s.depth  = geometry.depth * d;
        s.n_1    = elements(geometry.depth);
        s.n_2    = 1;
        s.h      = s.depth / s.n_1;
        s.P_wall = loading.wall_pressure * s.body_force * d;
        s.v_wall = loading.wall_speed * std::sqrt(m.G * d);
        s.u_end  = loading.wall_displacement * d;
        return s;
      }
    s.R_i   = geometry.inner_radius * d;
    s.R_o   = s.R_i + geometry.gap * d;
    s.n_1   = elements(geometry.gap);
    s.h     = (s.R_o - s.R_i) / s.n_1;
    s.u_end = s.R_i * loading.wall_rotation * M_PI / 180.;
    if (geometry.shape == "annulus row")
      {
        s.H          = s.h;
        s.n_2        = 1;
        s.P_wall     = loading.confining_pressure;
        s.v_wall     = loading.wall_speed * std::sqrt(s.P_wall / m.nonlocal.rho_s);
        s.body_force = 0.; // 6.2: no gravity
      }
    else
      {
        s.n_2    = elements(geometry.height);
        s.H      = geometry.height * d;
        s.P_wall = s.body_force * s.H; // hydrostatic pressure at the floor, the scale of Fig. 6
        s.v_wall = loading.wall_speed * std::sqrt(m.G * d);
      }
    return s;
  }

  std::vector<std::pair<std::string, double>>
  Parameters::fluidity_dirichlet() const
  {
    return parse_named_values(fluidity_bc.dirichlet, case_file,
                              "Fluidity boundary conditions/Dirichlet");
  }

  std::vector<double>
  Parameters::profile_depths() const
  {
    const std::string  entry = "Output/Profile depths";
    const std::string &list  = output.profile_depths;
    check_list_items(list, case_file, entry);
    const auto items = split_list(list);
    if (items.empty())
      return {};
    if (geometry.shape != "annulus" && geometry.shape != "annulus slice")
      throw InputError(case_file, entry,
                       "'" + list + "' does not apply to Geometry/Shape = " + geometry.shape +
                           ", whose one profile is profiles/velocity.csv: expected it empty");
    std::vector<double> depths;
    for (const auto &item : items)
      {
        double depth;
        try
          {
            depth = parse_number(item) + 0.; // + 0: -0 is 0
          }
        catch (const std::invalid_argument &)
          {
            throw InputError(case_file, entry,
                             "'" + item + "' in '" + list +
                                 "' is not a finite number: expected depths in grain diameters "
                                 "separated by commas");
          }
        if (!(depth >= 0. && depth <= geometry.height))
          {
            std::ostringstream s;
            s << "'" << item << "' in '" << list
              << "': expected a depth below the free surface in [0, " << geometry.height
              << "] grain diameters (Geometry/Height)";
            throw InputError(case_file, entry, s.str());
          }
        for (const double other : depths)
          if (profile_depth_name(other) == profile_depth_name(depth))
            throw InputError(case_file, entry,
                             "'" + list + "' gives the depth " + profile_depth_name(depth) +
                                 " twice (its file is named by the first 6 significant digits, "
                                 "velocity_at_depth_" +
                                 profile_depth_name(depth) + ".csv): expected each depth once");
        depths.push_back(depth);
      }
    return depths;
  }

  std::string
  profile_depth_name(const double depth)
  {
    std::ostringstream s;
    s << depth;
    return s.str();
  }

  std::vector<std::pair<std::string, double>>
  Parameters::fluidity_neumann() const
  {
    return parse_named_values(fluidity_bc.neumann, case_file,
                              "Fluidity boundary conditions/Neumann");
  }

  Parameters
  load_parameters(const std::string &case_file, const std::vector<Override> &overrides)
  {
    return load_case<Parameters>(case_file, overrides);
  }
} // namespace granflow::ngf
