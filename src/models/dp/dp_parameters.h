// Case-file parameters of the dp model (Daviet & Bertails-Descoubes 2016, creeping flow (23)-(24)).
// One struct per topic; each entry is declared once with its default, range and help text.
#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include "core/parameters.h"
#include "solvers/cone_problem.h"

#include <string>
#include <utility>
#include <vector>

namespace granflow::dp
{
  struct GeometryParameters
  {
    std::string  shape             = "channel"; // channel | square patch | half silo | cylinder channel | file
    std::string  mesh_file         = "";
    double       mesh_size         = 0.1;
    unsigned int refinements       = 0;
    double       channel_length    = 1.;
    double       channel_width     = 2.;
    double       cylinder_diameter = 0.25;
    double       patch_size        = 1.;
    double       silo_width        = 8.;
    double       silo_height       = 8.;
    double       aperture          = 1.;
    double       outlet_extension  = 1.;
  };

  struct RheologyParameters
  {
    double      mu                = 0.;  // friction coefficient (Mohr-Coulomb sin(phi) in 2D)
    double      Bi                = 0.;  // Bingham number sigma_0 / (rho g L)
    double      Re                = 1.;  // Reynolds number rho U L / eta
    double      b                 = 1.;  // bulk-viscosity parameter of D^b (Section 2)
    std::string viscosity         = "constant"; // constant | bagnold (eta = |D(u)|, 6.1.3)
    double      viscosity_floor   = 1e-3; // lower bound of eta for the bagnold law
  };

  struct BoundaryParameters
  {
    std::string no_slip;           // u = 0
    std::string velocity;          // "name: (u_x, u_y), ...": u = u_D, a constant per boundary
    std::string zero_x_velocity;   // u_x = 0, natural condition on the other component
    std::string zero_y_velocity;   // u_y = 0
    std::string zero_normal_velocity;     // u . n = 0, no tangential traction (free slip)
    std::string zero_tangential_velocity; // u . t = 0, normal traction as given (default 0)
    std::string external_pressure; // "name: p_ext, ...": traction sigma_ext n = -p_ext n (21)
    std::string external_stress;   // "name: (s_xx, s_xy, s_yy), ...": traction sigma_ext n (21)
    std::string analytic_traction; // "name, ...": traction of the case's analytic reference

    /// The velocity conditions: each one's boundary list and its entry (in Boundary conditions).
    std::vector<std::pair<const std::string *, const char *>>
    velocity_conditions() const
    {
      return {{&no_slip, "No-slip"},
              {&zero_x_velocity, "Zero x-velocity"},
              {&zero_y_velocity, "Zero y-velocity"},
              {&zero_normal_velocity, "Zero normal velocity"},
              {&zero_tangential_velocity, "Zero tangential velocity"}};
    }
  };

  struct SolverParameters
  {
    std::string  stress_element        = "P1d"; // P1d (constraints at quadrature points) | P1 (at nodes)
    std::string  method                = "fixed point"; // fixed point | interior point
    std::string  inner_solver          = "spg";         // pg | apgd | spg | ip (fixed point)
    std::string  residual              = "fischer-burmeister"; // or alart-curnier
    // Solver tunables default to the solver's own defaults (one place, DESIGN.md style 6).
    double       tolerance             = solvers::ConeSolverOptions{}.tolerance;
    unsigned int max_outer_iterations  = 500;
    unsigned int max_inner_iterations  = solvers::ConeSolverOptions{}.max_inner_iterations;
    unsigned int anderson_depth        = solvers::ConeSolverOptions{}.anderson_depth;
    double       max_seconds           = solvers::ConeSolverOptions{}.max_seconds; // 0: no limit
    unsigned int viscosity_iterations  = 50;
    double       viscosity_tolerance   = 1e-5;
    std::string  dump_cone_problem     = ""; // file name under the output directory, empty: none
  };

  struct OutputParameters
  {
    std::string  reference      = "none"; // none | bingham poiseuille | bagnold | cylinder
    std::string  profile_start   = "";     // "x, y"; both empty: the mesh's vertical middle line
    std::string  profile_end     = "";
    unsigned int profile_points = 101;
    std::string  drag_boundary  = "";   // boundary on which F_D = int lambda n . e_x is reported
    std::string  inflow_boundary = "";  // boundary whose mean normal velocity is U_infinity
    bool         write_vtu      = true;
  };

  struct Parameters
  {
    std::string          case_file;
    std::string          model = "dp";
    std::string          name  = ""; // Name; read_case() makes an empty one the case file's name
    GeometryParameters   geometry;
    RheologyParameters   rheology;
    std::string          gravity_direction = "0, -1"; // e_g (unit vector after normalisation)
    BoundaryParameters   boundaries;
    SolverParameters     solver;
    OutputParameters     output;

    void
    declare(dealii::ParameterHandler &prm);
    /// Entries holding a file name, relative to the case file's directory (parse_case_file).
    static std::vector<std::string>
    path_entries()
    {
      return {"Geometry/Mesh file"};
    }
    /// Checks what the patterns cannot (strict positivity, consistency); throws InputError.
    void
    validate() const;
    /// The Bingham reference holds for its boundary conditions only (6.1.1). Checked after the
    /// conditions have been checked against the mesh, whose errors name the mistake better.
    void
    require_reference_boundaries() const;
    dealii::Tensor<1, 2>
    e_g() const;
    /// One message per Geometry entry that Geometry/Shape does not use but that differs from its
    /// default: the run ignores it, and warns (a user varying the aperture or the mesh size with
    /// a mesh file got identical runs without a word). A warning, not an error, so that a case
    /// file can switch Shape and keep the other shape's entries.
    std::vector<std::string>
    ignored_geometry_entries() const;
  };

  /// Declares, parses `case_file` with the overrides and validates (InputError on bad input).
  Parameters
  load_parameters(const std::string &case_file, const std::vector<Override> &overrides = {});

  dealii::Point<2>
  parse_point(const std::string &text, const std::string &file, const std::string &entry);

  /// "name: (a, b, ...), name: (a, b, ...)" with one finite number per entry of `components`
  /// (their names, for the message) into pairs, each name once; throws InputError naming file and
  /// entry.
  std::vector<std::pair<std::string, std::vector<double>>>
  parse_named_tuples(const std::string &text, const std::string &file, const std::string &entry,
                     const std::vector<std::string> &components);

  /// Boundary conditions/Velocity: "name: (u_x, u_y), ..." (parse_named_tuples).
  std::vector<std::pair<std::string, dealii::Tensor<1, 2>>>
  parse_named_velocities(const std::string &text, const std::string &file,
                         const std::string &entry);

  /// Boundary conditions/External stress: "name: (s_xx, s_xy, s_yy), ..." (parse_named_tuples),
  /// the symmetric sigma_ext of (21).
  std::vector<std::pair<std::string, dealii::SymmetricTensor<2, 2>>>
  parse_named_stresses(const std::string &text, const std::string &file, const std::string &entry);
} // namespace granflow::dp
