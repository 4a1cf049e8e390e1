// Benchmark domains of Daviet & Bertails-Descoubes 2016 (Fig. 3 channel, Fig. 6 inclined layer,
// Fig. 8 half-silo with the Appendix B outlet extension, Fig. 12 cylinder in a channel) meshed with
// the Gmsh C++ API (built-in "geo" kernel), and import of user Gmsh meshes.
//
// Both paths end in build_mesh(), which turns the mesh of the current Gmsh model into a deal.II
// triangulation itself instead of going through GridIn::read_msh, because deal.II 9.4's reader
// (a) keeps clockwise triangles, whose measure and Jacobian are then negative, (b) maps a physical
// name to an id only through its "BoundaryID: n" syntax and otherwise falls back to the physical
// tag, and (c) calls gmsh::initialize/finalize itself. The ids assigned here are the physical tags,
// which is what GridIn assigns to plain names (checked in tests/unit/test_geometry.cc).
#include "geometry/geometry.h"

#include "core/errors.h"

#include <deal.II/base/exceptions.h>
#include <deal.II/base/numbers.h>
#include <deal.II/base/point.h>

#include <deal.II/grid/tria_description.h>

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

namespace granflow::geometry
{
  namespace
  {
    constexpr int gmsh_line     = 1; // 2-node line
    constexpr int gmsh_triangle = 2; // 3-node triangle

    // Catches a mesh size given in the wrong unit before Gmsh spends minutes and gigabytes on it.
    constexpr double max_cells = 1e7;

    /// Gmsh is one global state; the guard makes sure each use ends with finalize, even on error.
    class GmshSession
    {
    public:
      GmshSession()
      {
        // No gmshrc / gmsh-options: a user's Gmsh preferences must not change our meshes.
        gmsh::initialize(0, nullptr, false);
        gmsh::option::setNumber("General.Terminal", 0);
      }

      ~GmshSession()
      {
        gmsh::finalize();
      }

      GmshSession(const GmshSession &) = delete;
      GmshSession &
      operator=(const GmshSession &) = delete;
    };

    std::string
    str(double x)
    {
      std::ostringstream s;
      s << x;
      return s.str();
    }

    std::string
    str(const dealii::Point<2> &p)
    {
      return "(" + str(p[0]) + ", " + str(p[1]) + ")";
    }

    /// Value in (0, inf). `!(x > 0)` also rejects NaN.
    void
    require_positive(double x, const char *entry, const std::string &source)
    {
      if (!(x > 0) || !std::isfinite(x))
        throw InputError(source, entry, str(x) + " is out of range: expected a number in (0, inf)");
    }

    /// Value below `upper`; the message shows the bound as `bound` (e.g. "width = 1") and `why`.
    void
    require_below(double             x,
                  double             upper,
                  const char        *entry,
                  const std::string &bound,
                  const std::string &why,
                  const std::string &source)
    {
      if (!(x < upper))
        throw InputError(source,
                         entry,
                         str(x) + " is out of range: expected a number in (0, " + bound + ") " +
                           why);
    }

    /// h > 0, and not so small that the domain of area `area` gets more than max_cells triangles;
    /// then tells mesh.before_meshing the estimate.
    void
    check_mesh_size(Mesh &mesh, double h, double area, const std::string &source)
    {
      require_positive(h, entry::mesh_size, source);
      if (!std::isfinite(area))
        throw InputError(source, "Geometry",
                         "the domain's area is " + str(area) +
                             ": expected lengths whose product is a finite number");
      const double equilateral_area = std::sqrt(3.) / 4.;
      const double h_min            = std::sqrt(area / (max_cells * equilateral_area));
      if (h < h_min)
        throw InputError(source,
                         entry::mesh_size,
                         str(h) + " is out of range: expected a number in [" + str(h_min) +
                           ", inf) (a smaller size gives more than " + str(max_cells) +
                           " triangles)");
      if (mesh.before_meshing)
        mesh.before_meshing(area / (equilateral_area * h * h));
    }

    /// Undirected edge between two vertices.
    std::uint64_t
    edge_key(unsigned int a, unsigned int b)
    {
      if (a > b)
        std::swap(a, b);
      return (std::uint64_t(a) << 32) | b;
    }

    /// A problem with the mesh being read: InputError(source, entry, "<mesh_name> <problem>").
    struct MeshError
    {
      const std::string &source;
      const char        *entry;
      const std::string &mesh_name;

      InputError
      operator()(const std::string &problem) const
      {
        return InputError(source, entry, mesh_name + " " + problem);
      }
    };

    /// The current Gmsh model has 3-node triangles and no 3D elements.
    void
    check_element_types(const MeshError &error)
    {
      std::vector<int>                      types;
      std::vector<std::vector<std::size_t>> element_tags, node_tags;
      gmsh::model::mesh::getElements(types, element_tags, node_tags, 3, -1);
      if (!types.empty())
        throw error("has 3D elements: expected a 2D mesh of triangles");
      gmsh::model::mesh::getElements(types, element_tags, node_tags, 2, -1);
      if (types.empty())
        throw error("contains no triangles (when a mesh has physical groups, Gmsh saves only "
                    "their elements: put the domain in a Physical Surface)");
      for (const int type : types)
        if (type != gmsh_triangle)
          {
            std::string         name;
            int                 element_dim, order, n_nodes, n_primary_nodes;
            std::vector<double> local_coordinates;
            gmsh::model::mesh::getElementProperties(type, name, element_dim, order, n_nodes,
                                                    local_coordinates, n_primary_nodes);
            throw error("contains 2D elements of type '" + name +
                        "': expected only 3-node triangles (Mesh.ElementOrder = 1, no "
                        "recombination)");
          }
    }

    /// The triangles of the current Gmsh model as deal.II cells on their own vertices.
    struct Triangles
    {
      std::vector<dealii::Point<2>>                 vertices;
      std::vector<double>                           z;              // of each vertex
      std::unordered_map<std::size_t, unsigned int> vertex_of_node; // Gmsh node tag -> vertex
      std::vector<dealii::CellData<2>>              cells;
    };

    Triangles
    read_triangles(const MeshError &error)
    {
      std::vector<std::size_t> all_node_tags;
      std::vector<double>      all_coordinates, parametric;
      gmsh::model::mesh::getNodes(all_node_tags, all_coordinates, parametric, -1, -1, false, false);
      std::unordered_map<std::size_t, std::size_t> node_position;
      for (std::size_t i = 0; i < all_node_tags.size(); ++i)
        node_position[all_node_tags[i]] = i;

      // Only the nodes of triangles become vertices: Gmsh also stores geometry points and nodes of
      // curves that are not part of the domain.
      Triangles  mesh;
      const auto add_vertex = [&](std::size_t node) {
        const auto [it, inserted] = mesh.vertex_of_node.emplace(node, mesh.vertices.size());
        if (inserted)
          {
            const double *x = &all_coordinates[3 * node_position.at(node)];
            mesh.vertices.emplace_back(x[0], x[1]);
            mesh.z.push_back(x[2]);
          }
        return it->second;
      };

      std::vector<std::size_t> triangle_tags, triangle_nodes;
      gmsh::model::mesh::getElementsByType(gmsh_triangle, triangle_tags, triangle_nodes, -1);
      if (triangle_tags.empty())
        throw error("contains no triangles");
      // MSH 2 writes a triangle once for every physical surface it belongs to (a sub-region tagged
      // for post-processing, say): the copies would be cells of their own, and the faces between
      // them would no longer be boundary. A triangle is kept once, whatever its groups.
      mesh.cells.reserve(triangle_tags.size());
      std::set<std::array<std::size_t, 3>> seen;
      for (std::size_t t = 0; t < triangle_tags.size(); ++t)
        {
          std::array<std::size_t, 3> nodes = {
              {triangle_nodes[3 * t], triangle_nodes[3 * t + 1], triangle_nodes[3 * t + 2]}};
          std::sort(nodes.begin(), nodes.end());
          if (!seen.insert(nodes).second)
            continue;
          dealii::CellData<2> cell(3);
          for (unsigned int v = 0; v < 3; ++v)
            cell.vertices[v] = add_vertex(triangle_nodes[3 * t + v]);
          mesh.cells.push_back(std::move(cell));
        }
      return mesh;
    }

    /// All vertices in one plane z = const.
    void
    check_planar(const Triangles &mesh, const MeshError &error)
    {
      const auto &vertices = mesh.vertices;
      double      extent   = 0;
      for (const auto &p : vertices)
        extent =
            std::max({extent, std::abs(p[0] - vertices[0][0]), std::abs(p[1] - vertices[0][1])});
      for (std::size_t v = 0; v < mesh.z.size(); ++v)
        if (std::abs(mesh.z[v] - mesh.z[0]) > 1e-10 * extent)
          throw error("does not lie in a plane z = const: node at (x, y) = " + str(vertices[v]) +
                      " has z = " + str(mesh.z[v]) + ", the first node z = " + str(mesh.z[0]) +
                      " (expected a 2D mesh in the x-y plane)");
    }

    /// Gmsh orients triangles like the curve loop of their surface; deal.II needs them
    /// counterclockwise, or the mapping has a negative Jacobian. A degenerate triangle is refused.
    void
    orient_counterclockwise(Triangles &mesh, const MeshError &error)
    {
      for (auto &cell : mesh.cells)
        {
          const auto  &a     = mesh.vertices[cell.vertices[0]];
          const auto  &b     = mesh.vertices[cell.vertices[1]];
          const auto  &c     = mesh.vertices[cell.vertices[2]];
          const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
          const double longest =
            std::max({a.distance_square(b), b.distance_square(c), c.distance_square(a)});
          if (!(std::abs(cross) > 1e-12 * longest))
            throw error("has a degenerate triangle at " + str((a + b + c) / 3.));
          if (cross < 0)
            std::swap(cell.vertices[1], cell.vertices[2]);
        }
    }

    /// Edges of named physical curves -> physical tag. An edge on two named curves would get two
    /// boundary conditions; it is an error only if it is on the boundary, hence `conflict`.
    struct NamedEdges
    {
      struct Edge
      {
        int tag;
        int conflict = 0;
      };
      std::unordered_map<std::uint64_t, Edge> edges; // by edge_key() of the two vertices
      std::map<int, std::string>              name_of_tag;
    };

    NamedEdges
    read_named_edges(const Triangles &mesh, const MeshError &error)
    {
      NamedEdges       named;
      gmsh::vectorpair groups;
      gmsh::model::getPhysicalGroups(groups, 1);
      std::map<std::string, int> tag_of_name;
      for (const auto &[dim, tag] : groups)
        {
          std::string name;
          gmsh::model::getPhysicalName(dim, tag, name);
          if (name.empty())
            continue;
          if (!tag_of_name.emplace(name, tag).second)
            throw error("has two physical curves named '" + name + "' (tags " +
                        std::to_string(tag_of_name[name]) + " and " + std::to_string(tag) + ")");
          named.name_of_tag[tag] = name;

          std::vector<int> curves;
          gmsh::model::getEntitiesForPhysicalGroup(dim, tag, curves);
          for (const int curve : curves)
            {
              std::vector<int>                      types;
              std::vector<std::vector<std::size_t>> element_tags, node_tags;
              gmsh::model::mesh::getElements(types, element_tags, node_tags, 1, curve);
              for (std::size_t i = 0; i < types.size(); ++i)
                {
                  if (types[i] != gmsh_line)
                    throw error("has curve elements of Gmsh type " + std::to_string(types[i]) +
                                " in physical curve '" + name + "': expected 2-node lines");
                  for (std::size_t e = 0; e < element_tags[i].size(); ++e)
                    {
                      const auto a = mesh.vertex_of_node.find(node_tags[i][2 * e]);
                      const auto b = mesh.vertex_of_node.find(node_tags[i][2 * e + 1]);
                      // A curve off the triangulated surface bounds nothing.
                      if (a == mesh.vertex_of_node.end() || b == mesh.vertex_of_node.end())
                        continue;
                      const auto [it, inserted] = named.edges.emplace(
                          edge_key(a->second, b->second), NamedEdges::Edge{tag});
                      if (!inserted && it->second.tag != tag)
                        it->second.conflict = tag;
                    }
                }
            }
        }
      return named;
    }

    /// Two surfaces meshed apart (no shared nodes along their interface) would be two bodies
    /// joined at a few nodes, with a traction-free crack between them: boundary edges that
    /// overlap are refused. Edges are binned on a grid as fine as the longest one, so each is
    /// compared with its neighbours only.
    void
    check_conforming(const dealii::Triangulation<2> &triangulation, const MeshError &error)
    {
      std::vector<std::array<dealii::Point<2>, 2>> edges;
      double                                       longest = 0.;
      for (const auto &cell : triangulation.active_cell_iterators())
        for (const auto &face : cell->face_iterators())
          if (face->at_boundary())
            {
              edges.push_back({{face->vertex(0), face->vertex(1)}});
              longest = std::max(longest, face->vertex(0).distance(face->vertex(1)));
            }
      const auto bin = [&](const dealii::Point<2> &p) {
        return std::pair<long, long>(static_cast<long>(std::floor(p[0] / longest)),
                                     static_cast<long>(std::floor(p[1] / longest)));
      };
      std::map<std::pair<long, long>, std::vector<std::size_t>> bins;
      for (std::size_t e = 0; e < edges.size(); ++e)
        {
          const auto [x0, y0] = bin(edges[e][0]);
          const auto [x1, y1] = bin(edges[e][1]);
          for (long x = std::min(x0, x1); x <= std::max(x0, x1); ++x)
            for (long y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
              bins[{x, y}].push_back(e);
        }
      for (std::size_t e = 0; e < edges.size(); ++e)
        {
          const dealii::Point<2> m = 0.5 * (edges[e][0] + edges[e][1]);
          for (const std::size_t f : bins[bin(m)])
            {
              if (f == e)
                continue;
              const dealii::Tensor<1, 2> t = edges[f][1] - edges[f][0], r = m - edges[f][0];
              const double               s        = (r * t) / (t * t);
              const double               distance = std::abs(r[0] * t[1] - r[1] * t[0]) / t.norm();
              if (s > 1e-9 && s < 1. - 1e-9 && distance < 1e-9 * longest)
                throw error("has a non-conforming interface at " + str(m) +
                            ": two boundary edges overlap there (the surfaces on either side "
                            "do not share their nodes): expected one conforming mesh (in Gmsh, "
                            "Coherence or BooleanFragments before meshing)");
            }
        }
    }

    /// Each boundary face gets the tag of its named curve; every boundary face needs one.
    void
    assign_boundary_ids(Mesh &mesh, NamedEdges &named, const MeshError &error)
    {
      unsigned int     n_unnamed = 0;
      dealii::Point<2> first_unnamed;
      for (const auto &cell : mesh.triangulation.active_cell_iterators())
        for (const auto &face : cell->face_iterators())
          {
            if (!face->at_boundary())
              continue;
            const auto it =
                named.edges.find(edge_key(face->vertex_index(0), face->vertex_index(1)));
            if (it == named.edges.end())
              {
                if (n_unnamed++ == 0)
                  first_unnamed = face->center();
                continue;
              }
            if (it->second.conflict != 0)
              throw error("has a boundary edge at " + str(face->center()) +
                          " on two physical curves, '" + named.name_of_tag[it->second.tag] +
                          "' and '" + named.name_of_tag[it->second.conflict] +
                          "': expected exactly one");
            face->set_boundary_id(it->second.tag);
            mesh.boundary_ids[named.name_of_tag[it->second.tag]] = it->second.tag;
          }
      if (n_unnamed > 0)
        throw error("has " + std::to_string(n_unnamed) + " boundary edges, the first at " +
                    str(first_unnamed) +
                    ", on no named physical curve: every boundary needs a named Physical Curve");
    }

    /// Fills `mesh` from the mesh of the current Gmsh model. Problems are reported as
    /// InputError(source, entry, "<mesh_name> <problem>").
    void
    build_mesh(Mesh &mesh, const std::string &source, const char *entry,
               const std::string &mesh_name)
    {
      const MeshError error{source, entry, mesh_name};
      check_element_types(error);
      Triangles triangles = read_triangles(error);
      check_planar(triangles, error);
      orient_counterclockwise(triangles, error);
      NamedEdges named = read_named_edges(triangles, error);

      mesh.triangulation.clear();
      mesh.boundary_ids.clear();
      try
        {
          mesh.triangulation.create_triangulation(triangles.vertices, triangles.cells,
                                                  dealii::SubCellData());
        }
      catch (const dealii::ExceptionBase &e)
        {
          throw error("is not a valid triangulation: " + std::string(e.what()));
        }
      check_conforming(mesh.triangulation, error);
      assign_boundary_ids(mesh, named, error);
    }

    /// Meshes the current Gmsh model, writes it to `msh_path` and fills `mesh` from it. The file is
    /// written under a temporary name and renamed, so that a failure leaves no partial file.
    void
    mesh_and_write(Mesh &mesh, const std::string &msh_path, const std::string &source)
    {
      namespace fs = std::filesystem;
      const fs::path target(msh_path);
      const fs::path partial = target.parent_path() / (target.stem().string() + ".partial.msh");
      const auto     cannot_write = [&](const std::string &why) {
        return InputError(source + ": cannot write the mesh file '" + msh_path + "': " + why);
      };
      std::error_code ec;
      if (!target.parent_path().empty() && !fs::is_directory(target.parent_path(), ec))
        throw cannot_write("no directory '" + target.parent_path().string() + "'");

      gmsh::model::mesh::generate(2);
      try
        {
          gmsh::write(partial.string());
        }
      catch (const std::string &gmsh_error)
        {
          throw cannot_write(gmsh_error);
        }
      fs::rename(partial, target, ec);
      if (ec)
        throw cannot_write(ec.message());

      build_mesh(mesh, source, entry::mesh_size, "generated mesh '" + msh_path + "'");
    }

    /// Runs `body` in a Gmsh session; Gmsh reports errors by throwing std::string.
    template <typename Body>
    void
    with_gmsh(const std::string &source, const char *entry, const std::string &what, Body &&body)
    {
      try
        {
          const GmshSession session;
          body();
        }
      catch (const std::string &gmsh_error)
        {
          throw InputError(source, entry, what + ": Gmsh: " + gmsh_error);
        }
    }

    int
    add_point(double x, double y, double size)
    {
      return gmsh::model::geo::addPoint(x, y, 0., size);
    }

    /// Closed polygon through `points` (counterclockwise); line i joins points i and i + 1.
    std::vector<int>
    add_polygon_lines(const std::vector<int> &points)
    {
      std::vector<int> lines;
      for (std::size_t i = 0; i < points.size(); ++i)
        lines.push_back(gmsh::model::geo::addLine(points[i], points[(i + 1) % points.size()]));
      return lines;
    }

    /// Physical groups must be added after synchronize().
    void
    name_boundaries(const std::vector<std::pair<std::string, std::vector<int>>> &boundaries,
                    const std::vector<int>                                      &surfaces)
    {
      gmsh::model::geo::synchronize();
      for (const auto &[name, curves] : boundaries)
        gmsh::model::setPhysicalName(1, gmsh::model::addPhysicalGroup(1, curves), name);
      // Without a physical surface Gmsh would not save the triangles.
      gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, surfaces), "domain");
    }
  } // namespace

  dealii::types::boundary_id
  Mesh::id(const std::string &name, const std::string &context_file, const std::string &entry) const
  {
    const auto it = boundary_ids.find(name);
    if (it != boundary_ids.end())
      return it->second;
    std::string names;
    for (const auto &[known, id] : boundary_ids)
      names += (names.empty() ? "'" : ", '") + known + "'";
    // A case file's lists separate items with ',', a name from its value with ':' and a tuple with
    // '(', and trim spaces: a mesh name with one of these cannot be written there.
    std::string unwritable;
    for (const auto &[known, id] : boundary_ids)
      if (known.empty() || known.find_first_of(",:(#\t") != std::string::npos ||
          std::isspace(static_cast<unsigned char>(known.front())) ||
          std::isspace(static_cast<unsigned char>(known.back())))
        unwritable += (unwritable.empty() ? "'" : ", '") + known + "'";
    const auto        note = absent_boundary_notes.find(name);
    const std::string what =
        "the mesh has no boundary named '" + name + "': its boundaries are " +
        (names.empty() ? "(none)" : names) +
        (note != absent_boundary_notes.end() ? " (" + note->second + ")" : "") +
        (unwritable.empty() ? ""
                            : "; " + unwritable +
                                  " cannot be named in every entry of a case file (its lists "
                                  "split at ',', a value follows ':', a tuple starts at '(', '#' "
                                  "starts a comment, tabs become spaces and spaces at the ends "
                                  "are trimmed): rename the physical curve");
    if (entry.empty())
      throw InputError(context_file + ": " + what);
    throw InputError(context_file, entry, what);
  }

  void
  make_channel(Mesh              &mesh,
               double             length,
               double             width,
               double             h,
               const std::string &msh_path,
               const std::string &source)
  {
    require_positive(length, entry::length, source);
    require_positive(width, entry::width, source);
    check_mesh_size(mesh, h, length * width, source);

    with_gmsh(source, entry::mesh_size, "meshing the channel", [&] {
      gmsh::model::add("channel");
      const auto lines = add_polygon_lines({add_point(-length, -width / 2, h),
                                            add_point(0, -width / 2, h),
                                            add_point(0, width / 2, h),
                                            add_point(-length, width / 2, h)});
      const int  surface =
        gmsh::model::geo::addPlaneSurface({gmsh::model::geo::addCurveLoop(lines)});
      name_boundaries({{"bottom", {lines[0]}},
                       {"outlet", {lines[1]}},
                       {"top", {lines[2]}},
                       {"inlet", {lines[3]}}},
                      {surface});
      mesh_and_write(mesh, msh_path, source);
    });
  }

  void
  make_square_patch(Mesh              &mesh,
                    double             size,
                    double             h,
                    const std::string &msh_path,
                    const std::string &source)
  {
    require_positive(size, entry::size, source);
    check_mesh_size(mesh, h, size * size, source);

    with_gmsh(source, entry::mesh_size, "meshing the square patch", [&] {
      gmsh::model::add("square_patch");
      const auto lines = add_polygon_lines({add_point(0, 0, h),
                                            add_point(size, 0, h),
                                            add_point(size, size, h),
                                            add_point(0, size, h)});
      const int  surface =
        gmsh::model::geo::addPlaneSurface({gmsh::model::geo::addCurveLoop(lines)});
      name_boundaries({{"bed", {lines[0]}},
                       {"downstream", {lines[1]}},
                       {"surface", {lines[2]}},
                       {"upstream", {lines[3]}}},
                      {surface});
      mesh_and_write(mesh, msh_path, source);
    });
  }

  void
  make_half_silo(Mesh              &mesh,
                 double             W,
                 double             H,
                 double             D,
                 double             extension,
                 double             h,
                 const std::string &msh_path,
                 const std::string &source)
  {
    require_positive(W, entry::silo_width, source);
    require_positive(H, entry::silo_height, source);
    require_positive(D, entry::aperture, source);
    require_below(D, 2 * W, entry::aperture, "2 W = " + str(2 * W),
                  "so that the aperture half-width D/2 is less than the silo width W", source);
    if (!(extension >= 0) || !std::isfinite(extension))
      throw InputError(source,
                       entry::outlet_extension,
                       str(extension) + " is out of range: expected a number in [0, inf)");
    check_mesh_size(mesh, h, W * H + D / 2 * extension, source);

    with_gmsh(source, entry::mesh_size, "meshing the half-silo", [&] {
      gmsh::model::add("half_silo");
      namespace geo             = gmsh::model::geo;
      const int axis_bottom     = add_point(0, 0, h);
      const int aperture_corner = add_point(D / 2, 0, h);
      const int wall_bottom     = add_point(W, 0, h);
      const int wall_top        = add_point(W, H, h);
      const int axis_top        = add_point(0, H, h);
      // The aperture is a line of its own even when it is interior (extension > 0), so that the
      // discharge rate can be integrated over mesh edges.
      const int aperture = geo::addLine(axis_bottom, aperture_corner);
      const int bottom   = geo::addLine(aperture_corner, wall_bottom);
      const int wall     = geo::addLine(wall_bottom, wall_top);
      const int top      = geo::addLine(wall_top, axis_top);
      const int axis     = geo::addLine(axis_top, axis_bottom);
      const int silo =
        geo::addPlaneSurface({geo::addCurveLoop({aperture, bottom, wall, top, axis})});

      if (extension == 0)
        {
          name_boundaries({{"axis", {axis}},
                           {"wall", {wall}},
                           {"bottom", {bottom}},
                           {"top", {top}},
                           {"outlet", {aperture}}},
                          {silo});
        }
      else
        {
          const int outlet_axis      = add_point(0, -extension, h);
          const int outlet_corner    = add_point(D / 2, -extension, h);
          const int outlet           = geo::addLine(outlet_axis, outlet_corner);
          const int outlet_wall      = geo::addLine(outlet_corner, aperture_corner);
          const int outlet_axis_line = geo::addLine(axis_bottom, outlet_axis);
          const int tube             = geo::addPlaneSurface(
            {geo::addCurveLoop({outlet, outlet_wall, -aperture, outlet_axis_line})});
          name_boundaries({{"axis", {axis, outlet_axis_line}},
                           {"wall", {wall}},
                           {"bottom", {bottom}},
                           {"top", {top}},
                           {"outlet", {outlet}},
                           {"outlet_wall", {outlet_wall}}},
                          {silo, tube});
        }
      mesh_and_write(mesh, msh_path, source);
      mesh.absent_boundary_notes.clear();
      if (extension == 0)
        mesh.absent_boundary_notes["outlet_wall"] =
            "the half silo has an outlet_wall only below its outlet, when " +
            std::string(entry::outlet_extension) + " > 0";
    });
  }

  void
  make_cylinder_channel(Mesh              &mesh,
                        double             length,
                        double             width,
                        double             D,
                        double             h,
                        const std::string &msh_path,
                        const std::string &source)
  {
    require_positive(length, entry::length, source);
    require_positive(width, entry::width, source);
    require_positive(D, entry::diameter, source);
    require_below(D,
                  width,
                  entry::diameter,
                  "width = " + str(width),
                  "so that the cylinder fits in the channel",
                  source);
    require_below(D,
                  length,
                  entry::diameter,
                  "length = " + str(length),
                  "so that the cylinder fits in the channel",
                  source);
    // The cylinder is meshed at h / 3: below D = h / 2 it has fewer than 5 edges, and below
    // about 1e-8 Gmsh's mesher fails inside a parallel region, where its error cannot be caught.
    require_positive(h, entry::mesh_size, source);
    if (D < 0.5 * h)
      throw InputError(source, entry::diameter,
                       str(D) + " is too small for Geometry/Mesh size = " + str(h) +
                           " (the cylinder would have fewer than 5 edges): expected " +
                           (0.5 * h < std::min(width, length)
                                ? "a number in [" + str(0.5 * h) + ", " +
                                      str(std::min(width, length)) + "), or a smaller Mesh size"
                                : "a Mesh size of at most " + str(2 * D)));
    // Counts the zone within D of the cylinder, meshed up to three times finer, nine times.
    check_mesh_size(mesh, h,
                    length * width + 8 * std::min(length * width, 2 * dealii::numbers::PI * D * D),
                    source);

    with_gmsh(source, entry::mesh_size, "meshing the cylinder channel", [&] {
      gmsh::model::add("cylinder_channel");
      namespace geo                 = gmsh::model::geo;
      const auto             walls  = add_polygon_lines({add_point(-length / 2, -width / 2, h),
                                                         add_point(length / 2, -width / 2, h),
                                                         add_point(length / 2, width / 2, h),
                                                         add_point(-length / 2, width / 2, h)});
      const double           r      = D / 2;
      const int              centre = add_point(0, 0, h / 3);
      const std::vector<int> rim    = {add_point(r, 0, h / 3),
                                       add_point(0, r, h / 3),
                                       add_point(-r, 0, h / 3),
                                       add_point(0, -r, h / 3)};
      // Quarter arcs: Gmsh's circle arcs must span less than pi.
      std::vector<int> arcs;
      for (std::size_t i = 0; i < rim.size(); ++i)
        arcs.push_back(geo::addCircleArc(rim[i], centre, rim[(i + 1) % rim.size()]));
      const int surface = geo::addPlaneSurface({geo::addCurveLoop(walls), geo::addCurveLoop(arcs)});
      name_boundaries({{"walls", {walls[0], walls[2]}},
                       {"outlet", {walls[1]}},
                       {"inlet", {walls[3]}},
                       {"cylinder", arcs}},
                      {surface});

      // Size h/3 on the cylinder growing linearly to h at distance D: the drag (Daviet 6.3.1) is
      // a boundary integral over the cylinder.
      namespace field    = gmsh::model::mesh::field;
      const int distance = field::add("Distance");
      field::setNumbers(distance, "CurvesList", std::vector<double>(arcs.begin(), arcs.end()));
      field::setNumber(distance, "NumPointsPerCurve", 100);
      const int threshold = field::add("Threshold");
      field::setNumber(threshold, "InField", distance);
      field::setNumber(threshold, "SizeMin", h / 3);
      field::setNumber(threshold, "SizeMax", h);
      field::setNumber(threshold, "DistMin", 0);
      field::setNumber(threshold, "DistMax", D);
      field::setAsBackgroundMesh(threshold);
      gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
      gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
      gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);

      mesh_and_write(mesh, msh_path, source);
    });
  }

  void
  read_mesh_file(Mesh &mesh, const std::string &msh_file, const std::string &source)
  {
    std::error_code ec;
    if (std::filesystem::is_directory(msh_file, ec))
      throw InputError(source, entry::mesh_file,
                       "'" + msh_file + "' is a directory: expected a Gmsh .msh file");
    if (!std::filesystem::is_regular_file(msh_file, ec))
      throw InputError(source,
                       entry::mesh_file,
                       "cannot read the mesh file '" + msh_file + "': no such file");
    {
      // Every .msh (ASCII or binary, any version) begins with $MeshFormat; anything else (a .geo,
      // an image) would otherwise be opened by Gmsh as a geometry or fail deep inside it.
      std::ifstream in(msh_file, std::ios::binary);
      std::string   first;
      std::getline(in, first);
      if (first.rfind("$MeshFormat", 0) != 0)
        throw InputError(source, entry::mesh_file,
                         "'" + msh_file +
                             "' is not a Gmsh mesh file (it does not begin with $MeshFormat): "
                             "expected a .msh file (in Gmsh: File > Export, or gmsh -2 file.geo)");
      // Two physical groups of one dimension with one name: Gmsh keeps the name of only one of
      // them when it reads an MSH 2 file, and the other's edges would be reported as unnamed.
      // The $PhysicalNames section (text in every version) tells.
      std::string line;
      while (std::getline(in, line) && line.rfind("$PhysicalNames", 0) != 0)
        if (line.rfind("$Nodes", 0) == 0)
          break;
      if (line.rfind("$PhysicalNames", 0) == 0)
        {
          std::size_t count = 0;
          in >> count;
          std::map<std::pair<int, std::string>, int> tag_of;
          for (std::size_t k = 0; k < count && in; ++k)
            {
              int         dim = 0, tag = 0;
              std::string name;
              in >> dim >> tag;
              std::getline(in, name);
              const auto a = name.find('"'), b = name.rfind('"');
              name = a != std::string::npos && b > a ? name.substr(a + 1, b - a - 1) : name;
              if (const auto [it, fresh] = tag_of.emplace(std::make_pair(dim, name), tag);
                  !fresh && it->second != tag)
                throw InputError(source, entry::mesh_file,
                                 "mesh file '" + msh_file + "' has two physical " +
                                     (dim == 1   ? "curves"
                                      : dim == 2 ? "surfaces"
                                                 : "groups") +
                                     " named '" + name + "' (tags " + std::to_string(it->second) +
                                     " and " + std::to_string(tag) +
                                     "): expected one physical group per name");
            }
        }
    }

    with_gmsh(source, entry::mesh_file, "reading the mesh file '" + msh_file + "'", [&] {
      gmsh::open(msh_file);
      // Meshes merged from pieces repeat the nodes of their interfaces.
      gmsh::model::mesh::removeDuplicateNodes();
      build_mesh(mesh, source, entry::mesh_file, "mesh file '" + msh_file + "'");
    });
  }
} // namespace granflow::geometry
