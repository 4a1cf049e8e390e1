// Case-file parameters of the ngf model (Henann & Kamrin 2016): material (SI units, Section 6
// values as defaults), geometry and loading in the paper's dimensionless groups, fluidity boundary
// conditions, Newton and increment control, output. Converted to SI once, in Parameters::scales().
#pragma once

#include "core/parameters.h"
#include "rheology/finite_strain.h"
#include "rheology/nonlocal_fluidity.h"
#include "solvers/newton.h"

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <utility>
#include <vector>

namespace granflow::ngf
{
  struct MaterialParameters
  {
    rheology::NonlocalParameters nonlocal;
    rheology::ElasticModuli      elastic;
    double                       phi = 0.62; // solid volume fraction, b_0 = phi rho_s G (27)
    double                       G   = 9.81; // gravity [m/s^2]
  };

  struct GeometryParameters
  {
    std::string shape = "shear column"; // shear column (6.1) | annulus row (6.2) | annulus (6.3) |
                                        // annulus slice (6.3, 3D)
    double depth        = 20.;          // bed depth / d (shear column)
    double inner_radius = 60.;          // R_i / d (annulus)
    double gap          = 20.;          // (R_o - R_i) / d (annulus)
    double height       = 15.;          // H / d (annulus)
    double slice_angle  = 0.1;          // angle of the 3D slice [degrees] (annulus slice)
    double element_size = 1. / 3.;      // h / d
  };

  struct LoadingParameters
  {
    double wall_pressure      = 6.67;  // P_wall / (phi rho_s G d) (shear column)
    double confining_pressure = 1000.; // P_wall on the outer wall [Pa] (annulus row)
    double wall_speed         = 1e-3;  // dimensionless speed of the driven wall, see the help text
    double wall_displacement  = 1.;    // total wall displacement / d (shear column)
    double wall_rotation      = 4.;    // total rotation of the inner wall [degrees] (annulus)
  };

  struct FluidityBoundaryParameters
  {
    std::string dirichlet; // "name: g_wall [1/s], ..."; all other boundaries: Neumann
    std::string neumann;   // "name: zeta [1/(s m)], ..."; unnamed boundaries: zeta = 0
  };

  struct SolverParameters
  {
    std::string  fluidity  = "nonlocal";     // nonlocal | local (g = g_loc, Section 6.3 comparison)
    double tolerance = solvers::NewtonOptions{}.tolerance; // normalised R_u, R_g (Section 6.1)
    unsigned int max_iterations      = solvers::NewtonOptions{}.max_iterations; // per increment
    double       first_increment     = 1e-5; // wall displacement of the first shear increment / d
    double       max_increment       = 0.01; // largest wall displacement per increment / d
    double       growth              = 1.5;  // increment growth after an easy Newton solve
    bool reuse_factorization = solvers::NewtonOptions{}.reuse_factorization; // modified Newton
  };

  struct OutputParameters
  {
    std::string reference = "none"; // none | finite difference (the 1D reduction (90))
    bool        write_vtu = true;
    std::string profile_depths; // annulus with gravity: "depth / d, ..." below the free surface
  };

  /// SI values of the inputs. The driven wall moves by u_end at speed v_wall (an arc length
  /// R_i Omega t for the annulus).
  struct Scales
  {
    double       d, h, P_wall, v_wall, u_end, body_force;
    double       depth;       // shear column
    double       R_i, R_o, H; // annulus
    unsigned int n_1, n_2;    // elements along the shear gradient (z or R) and across it
  };

  struct Parameters
  {
    std::string                case_file;
    std::string                model = "ngf";
    std::string name = ""; // Name; read_case() makes an empty one the case file's name
    MaterialParameters         material;
    GeometryParameters         geometry;
    LoadingParameters          loading;
    FluidityBoundaryParameters fluidity_bc;
    SolverParameters           solver;
    OutputParameters           output;

    void
    declare(dealii::ParameterHandler &prm);
    /// Entries holding a file name (parse_case_file): none.
    static std::vector<std::string>
    path_entries()
    {
      return {};
    }
    /// Checks what the patterns cannot; throws InputError naming the file and the entry.
    void
    validate() const;
    Scales
    scales() const;
    std::vector<std::pair<std::string, double>>
    fluidity_dirichlet() const;
    std::vector<std::pair<std::string, double>>
    fluidity_neumann() const;
    /// Output/Profile depths: depths below the free surface of the annulus with gravity, in grain
    /// diameters, each in [0, Geometry/Height] and given once; throws InputError naming the entry.
    std::vector<double>
    profile_depths() const;
    /// Names of the boundaries of the geometry that a fluidity condition may name.
    std::vector<std::string>
    boundary_names() const;
  };

  Parameters
  load_parameters(const std::string &case_file, const std::vector<Override> &overrides = {});

  /// A depth of Output/Profile depths as it names its profile (velocity_at_depth_NAME.csv): the
  /// stream's default format, 6 significant digits ("7.5", "14.6667").
  std::string
  profile_depth_name(double depth);
} // namespace granflow::ngf
