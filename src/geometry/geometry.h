// Computational domains of the Daviet & Bertails-Descoubes 2016 benchmarks, meshed with straight
// triangles through the Gmsh C++ API: the Bingham Poiseuille channel (Fig. 3), the inclined layer
// of the Bagnold profile (Fig. 6), the half-silo (Fig. 8) with the outlet extension of Appendix B,
// and the channel around a cylinder (Fig. 12). Also imports a user's Gmsh mesh. Boundaries are
// addressed by the names of Gmsh physical curves. All lengths are dimensionless (L = 1).
//
// Gmsh keeps global state: none of these functions may run concurrently with another Gmsh user.
#pragma once

#include <deal.II/base/types.h>

#include <deal.II/grid/tria.h>

#include <functional>
#include <map>
#include <string>

namespace granflow::geometry
{
  /// Case-file entries the geometries are built from; error messages name them.
  namespace entry
  {
    inline constexpr const char *mesh_size        = "Geometry/Mesh size";
    inline constexpr const char *mesh_file        = "Geometry/Mesh file";
    inline constexpr const char *length           = "Geometry/Channel length";
    inline constexpr const char *width            = "Geometry/Channel width";
    inline constexpr const char *size             = "Geometry/Patch size";
    inline constexpr const char *silo_width       = "Geometry/Silo width";
    inline constexpr const char *silo_height      = "Geometry/Silo height";
    inline constexpr const char *aperture         = "Geometry/Aperture";
    inline constexpr const char *diameter         = "Geometry/Cylinder diameter";
    inline constexpr const char *outlet_extension = "Geometry/Outlet extension";
  } // namespace entry

  /// A triangle mesh whose boundary faces all carry the id of a named Gmsh physical curve.
  /// The id of a boundary is the tag of its physical curve, as deal.II's GridIn would assign it.
  struct Mesh
  {
    dealii::Triangulation<2> triangulation;

    /// Boundary name -> boundary id.
    std::map<std::string, dealii::types::boundary_id> boundary_ids;

    /// Boundary name -> why this mesh lacks it, for id()'s error (the half silo without an outlet
    /// extension has no outlet_wall).
    std::map<std::string, std::string> absent_boundary_notes;

    /// If set, called by a generator before Gmsh meshes, with its estimate of the number of
    /// triangles (Gmsh says nothing while it meshes, which takes minutes for millions).
    std::function<void(double triangles)> before_meshing;

    /// The id of boundary `name`. Throws InputError naming `context_file` (the case that needs the
    /// boundary), the `entry` that names it (if given), `name` and the names this mesh has.
    dealii::types::boundary_id
    id(const std::string &name, const std::string &context_file,
       const std::string &entry = "") const;
  };

  // Each generator validates its lengths and the target mesh size h (errors name the entries
  // above and `source`, the case file), writes the generated mesh to `msh_path` (Gmsh MSH 4.1, so
  // the user can inspect it) and fills `mesh`, replacing what it held.

  /// Daviet Fig. 3 (Bingham Poiseuille): x in [-length, 0], y in [-width/2, width/2].
  /// Boundaries "bottom" (y = -width/2), "top" (y = width/2), "inlet" (x = -length),
  /// "outlet" (x = 0).
  void
  make_channel(Mesh              &mesh,
               double             length,
               double             width,
               double             h,
               const std::string &msh_path,
               const std::string &source);

  /// Daviet Fig. 6 (Bagnold profile on an inclined plane, in the frame of the plane): [0, size]^2.
  /// Boundaries "bed" (y = 0), "surface" (y = size), "upstream" (x = 0), "downstream" (x = size).
  void
  make_square_patch(Mesh              &mesh,
                    double             size,
                    double             h,
                    const std::string &msh_path,
                    const std::string &source);

  /// Daviet Fig. 8: half-silo x in [0, W], y in [0, H] with an aperture of half-width D/2 at
  /// x in [0, D/2], y = 0, extended downward by [0, D/2] x [-extension, 0] (Appendix B).
  /// Boundaries "axis" (x = 0, symmetry, including the extension), "wall" (x = W), "bottom"
  /// (y = 0, x in [D/2, W]), "top" (y = H), "outlet" (y = -extension, x in [0, D/2]) and, if
  /// extension > 0, "outlet_wall" (x = D/2, y in [-extension, 0]). The mesh always has edges along
  /// the aperture y = 0, x in [0, D/2], so that the discharge rate can be measured there.
  void
  make_half_silo(Mesh              &mesh,
                 double             W,
                 double             H,
                 double             D,
                 double             extension,
                 double             h,
                 const std::string &msh_path,
                 const std::string &source);

  /// Daviet Fig. 12: x in [-length/2, length/2], y in [-width/2, width/2] minus the disc of
  /// diameter D centred at the origin. Boundaries "walls" (y = +-width/2), "cylinder",
  /// "inlet" (x = -length/2), "outlet" (x = length/2). The mesh size is h/3 on the cylinder and
  /// grows to h at a distance D from it. The cylinder is a polygon: refinement does not make it
  /// rounder.
  void
  make_cylinder_channel(Mesh              &mesh,
                        double             length,
                        double             width,
                        double             D,
                        double             h,
                        const std::string &msh_path,
                        const std::string &source);

  /// Reads a user's Gmsh mesh (any format Gmsh reads) of straight triangles in a plane z = const.
  /// Every named physical curve on the boundary becomes a boundary; every boundary edge must lie
  /// on exactly one named physical curve. Clockwise triangles are reoriented. Errors name `source`
  /// (the case file), the entry "Geometry/mesh file" and `msh_file`.
  void
  read_mesh_file(Mesh &mesh, const std::string &msh_file, const std::string &source);
} // namespace granflow::geometry
