#include "models/dp/dp_parameters.h"

#include "core/errors.h"
#include "core/format_number.h"
#include "core/output.h"
#include "core/parameters.h"
#include "geometry/geometry.h"
#include "solvers/cone_problem.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace granflow::dp
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
    prm.add_parameter("Model", model, "Model of this case file: dp (Daviet 2016).",
                      Selection("dp"));
    prm.add_parameter("Name", name,
                      "Name of the case, used in summary.json (empty: the case file's name "
                      "without .prm).",
                      Anything());
    prm.add_parameter(
        "Gravity direction", gravity_direction,
        "Direction e_g of the dimensionless body force (23), 'x, y' (finite, not both "
        "0; normalised).",
        Anything());

    prm.enter_subsection("Geometry");
    {
      auto &g = geometry;
      prm.add_parameter(
          "Shape", g.shape,
          "Built-in geometry of Daviet 2016 or a user mesh: channel (Fig. 3), "
          "square patch (inclined plane, Fig. 6), half silo (Fig. 8), cylinder channel "
          "(Fig. 12), file.",
          Selection("channel|square patch|half silo|cylinder channel|file"));
      prm.add_parameter(
          "Mesh file", g.mesh_file,
          "Gmsh .msh file with named physical curves (Shape = file); a relative path is "
          "relative to the case file's directory (given with --set: to the current directory).",
          Anything());
      prm.add_parameter("Mesh size", g.mesh_size, "Target element size h (units of L), > 0.",
                        Interval::positive());
      prm.add_parameter(
          "Global refinements", g.refinements,
          "Uniform refinements of the generated mesh, in [0, 10] (at most 1e7 triangles).",
          Integer(0, 10));
      prm.add_parameter("Channel length", g.channel_length,
                        "Channel length H (Fig. 3, Fig. 12), > 0.", Interval::positive());
      prm.add_parameter("Channel width", g.channel_width,
                        "Channel width (2L in Fig. 3, L in Fig. 12), > 0.", Interval::positive());
      prm.add_parameter("Cylinder diameter", g.cylinder_diameter,
                        "Cylinder diameter D (Fig. 12), in (0, channel width).",
                        Interval::positive());
      prm.add_parameter("Patch size", g.patch_size, "Side of the square patch, > 0.",
                        Interval::positive());
      prm.add_parameter("Silo width", g.silo_width, "Half-silo width W (Fig. 8), > 0.",
                        Interval::positive());
      prm.add_parameter("Silo height", g.silo_height, "Half-silo height H (Fig. 8), > 0.",
                        Interval::positive());
      prm.add_parameter("Aperture", g.aperture, "Silo aperture D (full width), > 0.",
                        Interval::positive());
      prm.add_parameter("Outlet extension", g.outlet_extension,
                        "Depth of the channel added below the outlet (Appendix B), >= 0.",
                        Double(0.));
    }
    prm.leave_subsection();

    prm.enter_subsection("Rheology");
    {
      auto &r = rheology;
      // In 2D mu = sin(phi), phi the angle of friction (Daviet & Bertails-Descoubes 2016, 3.1.1,
      // after (1)), so mu >= 1 is no material. (Near 1 the solvers fail: on a closed hopper at
      // mu = 2 both did, at mu = 1 the interior point did.)
      prm.add_parameter(
          "mu", r.mu,
          "Friction coefficient mu of DP(mu, Bi), in [0, 1): mu = sin(phi) in 2D, phi "
          "the angle of friction.",
          Interval(0., false, 1., true));
      prm.add_parameter("Bi", r.Bi, "Bingham number Bi = sigma_0 / (rho g L), >= 0.", Double(0.));
      prm.add_parameter("Re", r.Re,
                        "Reynolds number Re = rho U L / eta, in (0, 1e6] (the viscous term 2/Re "
                        "D(u) keeps the velocity operator A definite).",
                        Interval::positive(1e6));
      prm.add_parameter("b", r.b, "Bulk-viscosity parameter b of D^b(u), >= 0.", Double(0.));
      prm.add_parameter("Viscosity", r.viscosity,
                        "constant, or bagnold: eta = |D(u)| by fixed point (Daviet 6.1.3).",
                        Selection("constant|bagnold"));
      prm.add_parameter(
          "Viscosity floor", r.viscosity_floor,
          "Lower bound of eta for the bagnold law, eta = max(|D(u)|, floor), > 0, in the "
          "unit of |D(u)|, sqrt(g / L). Bagnold's |D(u)| scales as sqrt(Re): at "
          "small Re lower the floor with it (the run warns where it binds).",
          Interval::positive());
    }
    prm.leave_subsection();

    prm.enter_subsection("Boundary conditions");
    {
      auto &b = boundaries;
      prm.add_parameter("No-slip", b.no_slip, "Boundaries with u = 0, comma-separated names.",
                        Anything());
      prm.add_parameter(
          "Velocity", b.velocity,
          "'name: (u_x, u_y), ...': boundaries with a prescribed constant velocity u = u_D "
          "(a moving wall, an inflow), finite numbers. At a node shared with No-slip, Zero x- or "
          "Zero y-velocity, the components those fix stay zero (the end nodes of a moving lid "
          "between no-slip walls are at rest); at a node shared with Zero normal or tangential "
          "velocity, u = u_D; where two Velocity boundaries meet, the one listed first gives the "
          "node its value. In a domain closed by velocity conditions, they must not push "
          "material in: div u >= 0 (24).",
          Anything());
      prm.add_parameter("Zero x-velocity", b.zero_x_velocity,
                        "Boundaries with u_x = 0 (natural condition on u_y).", Anything());
      prm.add_parameter("Zero y-velocity", b.zero_y_velocity,
                        "Boundaries with u_y = 0 (natural condition on u_x).", Anything());
      prm.add_parameter(
          "Zero normal velocity", b.zero_normal_velocity,
          "Free-slip boundaries at any inclination: u . n = 0, no tangential traction. At a node "
          "n is the mean of its faces' normals weighted by the integral of its shape function on "
          "each; where the faces meet at more than 45 degrees, or meet another velocity "
          "condition in another direction, u = 0 at that node.",
          Anything());
      prm.add_parameter(
          "Zero tangential velocity", b.zero_tangential_velocity,
          "Boundaries at any inclination where the flow is normal to the boundary: u . t = 0, "
          "normal traction -p_ext (External pressure, default 0); e.g. the ends of a channel "
          "(Zero y-velocity on an end x = const). Nodes as for Zero normal velocity.",
          Anything());
      prm.add_parameter(
          "External pressure", b.external_pressure,
          "'name: p_ext, ...': traction -p_ext n on these boundaries (21), p_ext finite.",
          Anything());
      prm.add_parameter(
          "External stress", b.external_stress,
          "'name: (s_xx, s_xy, s_yy), ...': total traction sigma_ext n on these boundaries "
          "((20b) + (21)), with "
          "sigma_ext the constant symmetric stress [[s_xx, s_xy], [s_xy, s_yy]] (tension "
          "positive: a pressure p is s_xx = s_yy = -p), finite numbers; e.g. a shear load (s_xy, "
          "-p) on a face y = const. Only on a boundary with no velocity condition and no External "
          "pressure.",
          Anything());
      prm.add_parameter("Analytic traction", b.analytic_traction,
                        "Boundaries loaded by the traction of the analytic reference (bagnold).",
                        Anything());
    }
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    {
      auto &s = solver;
      prm.add_parameter(
          "Stress element", s.stress_element,
          "P1d: discontinuous P1 stress, constraints at the 3 quadrature points of each "
          "triangle (Property 3); P1: continuous P1 stress, constraints at the nodes "
          "(trapezoidal rule, 4.3.5).",
          Selection("P1d|P1"));
      prm.add_parameter(
          "Method", s.method,
          "fixed point: Cadoux's fixed point on s = mu |gamma_T| (Algorithm 1), each "
          "step a cone QP solved by the inner solver; any mu >= 0, Bi >= 0. interior "
          "point: primal-dual interior point (mu > 0 or Bi > 0) on the split form of "
          "the law, then, where that stalls and Bi = 0, on the whole problem, then, where "
          "that stalls too, Cadoux's fixed point with interior-point steps from its best "
          "iterate; reaches tight tolerances where the fixed point stalls, but can stop "
          "above them on fine meshes and at high friction (docs/solvers.md).",
          Selection("fixed point|interior point"));
      prm.add_parameter(
          "Inner solver", s.inner_solver,
          "Inner SOCQP solver: pg (projected gradient + line search), apgd (Nesterov), "
          "spg (spectral projected gradient), ip (interior point on each step, 4.4.2: "
          "mu > 0 and Bi = 0; far slower per step, each solved to 0.1 of the outer residual; "
          "on a refined silo it got lower than the first-order steps: docs/solvers.md).",
          Selection("pg|apgd|spg|ip"));
      prm.add_parameter("Residual", s.residual,
                        "Stopping residual: fischer-burmeister (Bi = 0 points) or alart-curnier.",
                        Selection("fischer-burmeister|alart-curnier"));
      prm.add_parameter("Tolerance", s.tolerance,
                        "Infinity norm of the residual to reach, in units of stress, in (0, 0.1].",
                        Interval::positive(0.1));
      prm.add_parameter("Max outer iterations", s.max_outer_iterations,
                        "Cadoux fixed-point iterations (interior point: its iterations) before "
                        "giving up, >= 1.",
                        Integer(1));
      prm.add_parameter("Max inner iterations", s.max_inner_iterations,
                        "Inner solver iterations per fixed-point iteration, >= 1.", Integer(1));
      prm.add_parameter(
          "Max seconds", s.max_seconds,
          "Wall-time limit of each cone solve in seconds, >= 0 (0: none). The fixed point's "
          "first-order inner solver stops at it; the interior point, and the fixed point with "
          "ip steps, start no iteration or step that would, at the last one's duration, end "
          "past it. A solve stopped by it "
          "keeps its iterate of least residual and the run exits with status 3.",
          Double(0.));
      prm.add_parameter(
          "Anderson depth", s.anderson_depth,
          "Anderson acceleration of the Cadoux fixed point on s (0: plain Algorithm 1; "
          "the plain iteration can cycle for mu >= 0.5), in [0, 20].",
          Integer(0, 20));
      prm.add_parameter("Viscosity iterations", s.viscosity_iterations,
                        "Fixed-point iterations on eta(x) (bagnold), >= 1.", Integer(1));
      prm.add_parameter(
          "Viscosity tolerance", s.viscosity_tolerance,
          "The eta fixed point (bagnold) ends when eta = |D(u)| of a solve's velocity differs "
          "from the viscosity that solve used by less than this (relative, L2 over the "
          "domain), > 0.",
          Interval::positive());
      prm.add_parameter("Dump cone problem", s.dump_cone_problem,
                        "If set, the cone problem is written to this file: a name relative to the "
                        "output directory, or a path outside it (a path into it is refused; replay "
                        "with build/bench/replay_cone_problem, docs/solvers.md).",
                        Anything());
    }
    prm.leave_subsection();

    prm.enter_subsection("Output");
    {
      auto &o = output;
      prm.add_parameter("Reference", o.reference,
                        "Analytic reference compared with the profile: none, bingham poiseuille "
                        "(6.1.1), bagnold (6.1.3).",
                        Selection("none|bingham poiseuille|bagnold"));
      prm.add_parameter("Profile start", o.profile_start,
                        "Start 'x, y' of the line profiles/velocity.csv samples; empty, with "
                        "Profile end empty too: the vertical line through the middle of the "
                        "mesh's bounding box, from its bottom to its top.",
                        Anything());
      prm.add_parameter("Profile end", o.profile_end,
                        "End 'x, y' of the sampled line; empty: see Profile start.", Anything());
      prm.add_parameter(
          "Profile points", o.profile_points,
          "Samples along the line, in [2, 100000]; those outside the mesh are left out.",
          Integer(2, 100000));
      prm.add_parameter("Drag boundary", o.drag_boundary,
                        "Boundary with a velocity condition on which the drag F_D = int lambda n . "
                        "e_x (6.3.1) and "
                        "the material's force (boundary_force, with its viscous part) are "
                        "computed, from the reaction of the momentum equation; with Shape = "
                        "cylinder channel also the wake, the upstream pressure peak and (with "
                        "Inflow boundary) Fr and C_D.",
                        Anything());
      prm.add_parameter("Inflow boundary", o.inflow_boundary,
                        "Boundary whose mean velocity is U_infinity (Fr, C_D of 6.3.1).",
                        Anything());
      prm.add_parameter("Write vtu", o.write_vtu, "Write solution-0000.vtu and solution.pvd.",
                        Bool());
    }
    prm.leave_subsection();
  }

  void
  Parameters::validate() const
  {
    const std::string &f = case_file;
    for (const auto &[list, entry] : boundaries.velocity_conditions())
      check_list_items(*list, f, std::string("Boundary conditions/") + entry);
    check_list_items(boundaries.analytic_traction, f, "Boundary conditions/Analytic traction");
    check_list_items(boundaries.external_pressure, f, "Boundary conditions/External pressure");
    parse_named_velocities(boundaries.velocity, f, "Boundary conditions/Velocity");
    parse_named_stresses(boundaries.external_stress, f, "Boundary conditions/External stress");
    // The split form's friction cone ||lambda_T|| <= Bi + mu lambda_N needs an interior.
    if (solvers::parse_cone_method(solver.method) == solvers::ConeMethod::interior_point &&
        !(rheology.mu > 0. || rheology.Bi > 0.))
      throw InputError(f, "Solver/Method",
                       "= interior point needs Rheology/mu > 0 or Rheology/Bi > 0 (at mu = Bi = 0 "
                       "the stress has no deviatoric part to solve for); use fixed point");
    // Each step is the whole-form interior point's convex problem, which needs a cone with an
    // interior and no truncation.
    if (solvers::parse_cone_method(solver.method) == solvers::ConeMethod::fixed_point &&
        solver.inner_solver == "ip" && !(rheology.mu > 0. && rheology.Bi == 0.))
      throw InputError(f, "Solver/Inner solver",
                       "= ip needs Rheology/mu > 0 and Rheology/Bi = 0 (its interior point solves "
                       "the cones of DP(mu, 0)); use pg, apgd or spg");
    if (!solver.dump_cone_problem.empty() && OutputDirectory::is_run_file(solver.dump_cone_problem))
      throw InputError(f, "Solver/Dump cone problem",
                       "= " + solver.dump_cone_problem +
                           ": the run writes a file of that name, which would replace the dump: "
                           "expected another name (e.g. cone.bin)");
    if (geometry.shape == "file" && geometry.mesh_file.empty())
      throw InputError(f, "Geometry/Mesh file", "is empty: Shape = file needs a .msh file");
    if (!boundaries.analytic_traction.empty() && output.reference != "bagnold")
      throw InputError(f, "Boundary conditions/Analytic traction",
                       "needs an analytic reference with stresses: set Output/Reference = bagnold");
    // An analytic reference holds only for the problem it solves; anywhere else its
    // max_rel_error would be a silent wrong answer (or NaN).
    const dealii::Tensor<1, 2> g = e_g();
    // The reference's domain: the built-in `shape` with its `size_entry` at the paper's value (a
    // user mesh of it, Shape = file, is the user's to get right).
    const auto require_domain = [&](const std::string &solves, const std::string &shape,
                                    const std::string &size_entry, const double size,
                                    const double paper_size) {
      if (geometry.shape != shape && geometry.shape != "file")
        throw InputError(f, "Output/Reference",
                         solves + ": needs Geometry/Shape = " + shape + " (or a mesh file of it)");
      if (geometry.shape == shape && size != paper_size)
        throw InputError(f, "Output/Reference",
                         solves + ": needs Geometry/" + size_entry + " = " +
                             std::to_string(static_cast<int>(paper_size)));
    };
    if (output.reference == "bingham poiseuille")
      {
        require_domain("'bingham poiseuille' solves the channel y in [-1, 1] (6.1.1)", "channel",
                       "Channel width", geometry.channel_width, 2.);
        if (rheology.mu != 0. || rheology.viscosity != "constant")
          throw InputError(f, "Output/Reference",
                           "'bingham poiseuille' needs Rheology/mu = 0 and Rheology/Viscosity = "
                           "constant (6.1.1)");
        if (g[0] != 1.)
          throw InputError(f, "Output/Reference",
                           "'bingham poiseuille' is driven along the channel: needs Gravity "
                           "direction = 1, 0");
        // The wall's shear stress is 1 (the channel's half-width times the unit body force):
        // at Bi >= 1 the channel is at rest, u = 0, and a relative error has no scale.
        if (rheology.Bi >= 1.)
          throw InputError(
              f, "Output/Reference",
              "'bingham poiseuille' compares a flowing channel, and at Rheology/Bi = " +
                  format_number(rheology.Bi) +
                  " it is at rest (the yield stress Bi reaches the wall's shear "
                  "stress 1): expected Rheology/Bi in [0, 1), or Output/Reference = "
                  "none");
      }
    if (output.reference == "bagnold")
      {
        require_domain("'bagnold' solves the layer y in [0, 1] (6.1.3)", "square patch",
                       "Patch size", geometry.patch_size, 1.);
        if (rheology.Bi != 0. || rheology.viscosity != "bagnold")
          throw InputError(
              f, "Output/Reference",
              "'bagnold' needs Rheology/Bi = 0 and Rheology/Viscosity = bagnold (6.1.3)");
        // The layer flows only above the friction angle: sin a > mu cos a with e_g = (sin a,
        // -cos a).
        if (!(g[1] < 0. && g[0] > -rheology.mu * g[1]))
          throw InputError(f, "Output/Reference",
                           "'bagnold' needs a flowing layer: Gravity direction (sin a, -cos a) "
                           "with tan a > Rheology/mu (" +
                               (g[1] < 0.
                                    ? "here tan a = " + format_number(-g[0] / g[1])
                                    : std::string("here gravity does not point into the bed")) +
                               ")");
      }
    if (output.profile_start.empty() != output.profile_end.empty())
      throw InputError(f,
                       output.profile_start.empty() ? "Output/Profile end" : "Output/Profile start",
                       "is set while Output/Profile " +
                           std::string(output.profile_start.empty() ? "start" : "end") +
                           " is empty: expected both points of the line, or neither (the mesh's "
                           "vertical middle line)");
    if (!output.profile_start.empty() &&
        parse_point(output.profile_start, f, "Output/Profile start") ==
            parse_point(output.profile_end, f, "Output/Profile end"))
      throw InputError(f, "Output/Profile end",
                       "'" + output.profile_end +
                           "' is the point Output/Profile start names: expected the other end "
                           "of a line");
  }

  void
  Parameters::require_reference_boundaries() const
  {
    const std::string &f = case_file;
    // Neither reference has a moving boundary or a stress load other than its own.
    if (output.reference != "none")
      for (const auto &[text, entry, what] :
           {std::make_tuple(&boundaries.velocity, "Velocity", "moving boundary"),
            std::make_tuple(&boundaries.external_stress, "External stress", "external stress")})
        if (!trim(*text).empty())
          throw InputError(f, std::string("Boundary conditions/") + entry,
                           "is set, but Output/Reference = " + output.reference +
                               " solves the paper's problem, which has no " + what +
                               ": expected it empty, or Output/Reference = none");
    // The Bingham reference (6.1.1) is (23)-(24) with u = 0 on the walls y = +-1 and the ends
    // free along the channel, under one pressure or none (which does not change a flow at mu =
    // 0); with other conditions its max_rel_error would be a silent wrong answer.
    if (output.reference == "bingham poiseuille" && geometry.shape == "channel")
      {
        const auto           &bc    = boundaries;
        const auto            walls = split_list(bc.no_slip);
        std::set<std::string> free_ends;
        for (const auto *list : {&bc.zero_y_velocity, &bc.zero_tangential_velocity})
          for (const auto &name : split_list(*list))
            free_ends.insert(name);
        if (std::set<std::string>(walls.begin(), walls.end()) !=
                std::set<std::string>{"bottom", "top"} ||
            free_ends != std::set<std::string>{"inlet", "outlet"} ||
            !split_list(bc.zero_x_velocity).empty() || !split_list(bc.zero_normal_velocity).empty())
          throw InputError(f, "Output/Reference",
                           "'bingham poiseuille' solves the channel with no-slip walls and free "
                           "ends (6.1.1): needs Boundary conditions/No-slip = bottom, top, and "
                           "the ends (inlet, outlet) free along the channel (Zero y-velocity or "
                           "Zero tangential velocity)");
        std::map<std::string, double> pressure{{"inlet", 0.}, {"outlet", 0.}};
        for (const auto &[name, value] :
             parse_named_values(bc.external_pressure, f, "Boundary conditions/External pressure"))
          pressure[name] = value;
        if (pressure["inlet"] != pressure["outlet"])
          throw InputError(f, "Output/Reference",
                           "'bingham poiseuille' is driven by the body force alone: needs "
                           "Boundary conditions/External pressure equal at inlet and outlet (a "
                           "pressure difference drives another flow)");
      }
    // The Bagnold reference (6.1.3) is the layer on a no-slip bed with a free surface, its ends
    // loaded by the analytic stress; without those tractions the layer is another flow.
    if (output.reference == "bagnold" && geometry.shape == "square patch")
      {
        const auto &bc  = boundaries;
        const auto  bed = split_list(bc.no_slip), ends = split_list(bc.analytic_traction);
        bool        other_condition = false;
        for (const auto &[list, entry] : bc.velocity_conditions())
          other_condition = other_condition || (list != &bc.no_slip && !split_list(*list).empty());
        bool pressed = false;
        for (const auto &[name, value] :
             parse_named_values(bc.external_pressure, f, "Boundary conditions/External pressure"))
          pressed = pressed || value != 0.;
        if (bed != std::vector<std::string>{"bed"} ||
            std::set<std::string>(ends.begin(), ends.end()) !=
                std::set<std::string>{"upstream", "downstream"} ||
            other_condition || pressed)
          throw InputError(f, "Output/Reference",
                           "'bagnold' solves the layer on a no-slip bed with a free surface and "
                           "the analytic stress on its ends (6.1.3): needs Boundary "
                           "conditions/No-slip = bed, Analytic traction = upstream, downstream, "
                           "and no other velocity condition or External pressure");
      }
  }

  Parameters
  load_parameters(const std::string &case_file, const std::vector<Override> &overrides)
  {
    return load_case<Parameters>(case_file, overrides);
  }

  namespace
  {
    /// Exactly `count` comma-separated finite numbers ("1,,0" is not two: split_list would drop
    /// the empty item); throws std::invalid_argument or parse_number's error otherwise.
    std::vector<double>
    parse_numbers(const std::string &text, const std::size_t count)
    {
      std::vector<double> values;
      std::size_t         from = 0;
      for (;;)
        {
          const std::size_t comma = text.find(',', from);
          values.push_back(parse_number(text.substr(from, comma - from)));
          if (comma == std::string::npos)
            break;
          from = comma + 1;
        }
      if (values.size() != count)
        throw std::invalid_argument("");
      return values;
    }
  } // namespace

  dealii::Point<2>
  parse_point(const std::string &text, const std::string &file, const std::string &entry)
  {
    try
      {
        const std::vector<double> x = parse_numbers(text, 2);
        return {x[0], x[1]};
      }
    catch (const std::exception &)
      {
        throw InputError(file, entry,
                         "'" + text + "' is not a point: expected 'x, y' (finite numbers)");
      }
  }

  std::vector<std::pair<std::string, std::vector<double>>>
  parse_named_tuples(const std::string &text, const std::string &file, const std::string &entry,
                     const std::vector<std::string> &components)
  {
    std::string tuple = "(";
    for (const std::string &c : components)
      tuple += (tuple.size() > 1 ? ", " : "") + c;
    tuple += ")";
    std::vector<std::pair<std::string, std::vector<double>>> result;
    if (trim(text).empty())
      return result;
    const auto refuse = [&](const std::string &what) {
      throw InputError(file, entry,
                       "cannot read '" + trim(what) + "': expected 'boundary: " + tuple +
                           ", ...' (finite numbers)");
    };
    std::size_t at = 0;
    while (at < text.size())
      {
        // one item, "name: (x, y, ...)", then a comma or the end
        const std::size_t start = at;
        const std::size_t colon = text.find(':', at), open = text.find('(', at);
        const std::size_t close = open == std::string::npos ? open : text.find(')', open);
        if (colon == std::string::npos || open == std::string::npos || close == std::string::npos ||
            colon > open || !trim(text.substr(colon + 1, open - colon - 1)).empty())
          refuse(text.substr(at));
        const std::string name = trim(text.substr(at, colon - at));
        if (name.empty() || name.find(',') != std::string::npos)
          refuse(text.substr(at, close + 1 - at));
        std::vector<double> values;
        try
          {
            values = parse_numbers(text.substr(open + 1, close - open - 1), components.size());
          }
        catch (const std::exception &)
          {
            refuse(text.substr(at, close + 1 - at));
          }
        result.emplace_back(name, values);
        require_last_name_new(result, file, entry);
        at = close + 1;
        while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at])))
          ++at;
        if (at < text.size())
          {
            const std::string item = "after '" + trim(text.substr(start, close + 1 - start)) + "'";
            if (text[at] != ',')
              throw InputError(file, entry,
                               item + " comes '" + trim(text.substr(at)) +
                                   "': expected ',' between items 'boundary: " + tuple + "'");
            if (trim(text.substr(at + 1)).empty())
              throw InputError(file, entry,
                               item +
                                   " comes a ',' and nothing: expected another item "
                                   "'boundary: " +
                                   tuple + "' or no comma");
            ++at;
          }
      }
    return result;
  }

  std::vector<std::pair<std::string, dealii::Tensor<1, 2>>>
  parse_named_velocities(const std::string &text, const std::string &file, const std::string &entry)
  {
    std::vector<std::pair<std::string, dealii::Tensor<1, 2>>> result;
    for (const auto &[name, u] : parse_named_tuples(text, file, entry, {"u_x", "u_y"}))
      result.emplace_back(name, dealii::Tensor<1, 2>({u[0], u[1]}));
    return result;
  }

  std::vector<std::pair<std::string, dealii::SymmetricTensor<2, 2>>>
  parse_named_stresses(const std::string &text, const std::string &file, const std::string &entry)
  {
    std::vector<std::pair<std::string, dealii::SymmetricTensor<2, 2>>> result;
    for (const auto &[name, s] : parse_named_tuples(text, file, entry, {"s_xx", "s_xy", "s_yy"}))
      {
        dealii::SymmetricTensor<2, 2> sigma;
        sigma[0][0] = s[0];
        sigma[0][1] = s[1];
        sigma[1][1] = s[2];
        result.emplace_back(name, sigma);
      }
    return result;
  }

  std::vector<std::string>
  Parameters::ignored_geometry_entries() const
  {
    const GeometryParameters &g = geometry, defaults{};
    const std::string        &s = g.shape;
    const bool channel = s == "channel", cylinder = s == "cylinder channel", file = s == "file";
    namespace names = granflow::geometry::entry;
    const struct
    {
      const char *entry;
      double      value, default_value;
      bool        used;
    } entries[] = {
        {names::mesh_size, g.mesh_size, defaults.mesh_size, !file},
        {names::length, g.channel_length, defaults.channel_length, channel || cylinder},
        {names::width, g.channel_width, defaults.channel_width, channel || cylinder},
        {names::diameter, g.cylinder_diameter, defaults.cylinder_diameter, cylinder},
        {names::size, g.patch_size, defaults.patch_size, s == "square patch"},
        {names::silo_width, g.silo_width, defaults.silo_width, s == "half silo"},
        {names::silo_height, g.silo_height, defaults.silo_height, s == "half silo"},
        {names::aperture, g.aperture, defaults.aperture, s == "half silo"},
        {names::outlet_extension, g.outlet_extension, defaults.outlet_extension, s == "half silo"}};
    std::vector<std::string> messages;
    for (const auto &e : entries)
      if (!e.used && e.value != e.default_value)
        {
          std::ostringstream m;
          m << e.entry << " = " << e.value << " is not used by Geometry/Shape = " << s
            << " and has no effect on this run"
            << (file ? " (the mesh is Geometry/Mesh file's, refined by Global refinements)" : "");
          messages.push_back(m.str());
        }
    if (!file && !g.mesh_file.empty())
      messages.push_back(std::string(names::mesh_file) + " = " + g.mesh_file +
                         " is not used by Geometry/Shape = " + s +
                         " and has no effect on this run (set Shape = file to use it)");
    return messages;
  }

  dealii::Tensor<1, 2>
  Parameters::e_g() const
  {
    dealii::Point<2> g = parse_point(gravity_direction, case_file, "Gravity direction");
    // scaled by its largest component first, so that a length beyond the largest double (1e308,
    // 1e308) is still a direction
    const double largest = std::max(std::abs(g[0]), std::abs(g[1]));
    if (largest == 0.)
      throw InputError(case_file, "Gravity direction", "is the zero vector: expected a direction");
    g /= largest;
    return g / g.norm();
  }
} // namespace granflow::dp
