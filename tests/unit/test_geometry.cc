// Unit tests of the benchmark geometries of Daviet & Bertails-Descoubes 2016 (channel Fig. 3,
// inclined layer Fig. 6, half-silo Fig. 8 + Appendix B, cylinder channel Fig. 12) and of Gmsh mesh
// import: areas, boundary names, positions and lengths, mesh-size scaling, uniform refinement,
// simplex finite elements on the meshes, agreement of the boundary ids with deal.II's GridIn, and
// the InputError messages for bad input.
#include "geometry/geometry.h"

#include "core/errors.h"
#include "postprocess/profiles.h"

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>

#include <deal.II/grid/grid_in.h>

#include <deal.II/lac/vector.h>

#include <deal.II/numerics/vector_tools.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace
{
  using namespace dealii;
  using granflow::InputError;
  using granflow::geometry::Mesh;
  namespace fs = std::filesystem;

  constexpr double pi = numbers::PI;

  /// Each test writes its meshes into a directory of its own, removed afterwards.
  class Geometry : public ::testing::Test
  {
  protected:
    void
    SetUp() override
    {
      const auto *test = ::testing::UnitTest::GetInstance()->current_test_info();
      dir              = fs::temp_directory_path() /
            ("granflow_test_geometry_" + std::to_string(::getpid()) + "_" + test->name());
      fs::create_directories(dir);
    }

    void
    TearDown() override
    {
      fs::remove_all(dir);
    }

    std::string
    path(const std::string &name) const
    {
      return (dir / name).string();
    }

    fs::path dir;
  };

  double
  area_from_measures(const Triangulation<2> &tria)
  {
    double area = 0;
    for (const auto &cell : tria.active_cell_iterators())
      area += cell->measure();
    return area;
  }

  /// Independent of cell->measure(): quadrature with the simplex mapping.
  double
  area_from_quadrature(const Triangulation<2> &tria)
  {
    const FE_SimplexP<2>   fe(1);
    const MappingFE<2>     mapping(fe);
    const QGaussSimplex<2> quadrature(1);
    FEValues<2>            fe_values(mapping, fe, quadrature, update_JxW_values);
    double                 area = 0;
    for (const auto &cell : tria.active_cell_iterators())
      {
        fe_values.reinit(cell);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          area += fe_values.JxW(q);
      }
    return area;
  }

  std::map<types::boundary_id, double>
  boundary_lengths(const Triangulation<2> &tria)
  {
    std::map<types::boundary_id, double> lengths;
    for (const auto &cell : tria.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary())
          lengths[face->boundary_id()] += face->measure();
    return lengths;
  }

  /// Mean length of the boundary edges with id `id`.
  double
  mean_edge_length(const Triangulation<2> &tria, types::boundary_id id)
  {
    double       sum = 0;
    unsigned int n   = 0;
    for (const auto &cell : tria.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary() && face->boundary_id() == id)
          {
            sum += face->measure();
            ++n;
          }
    return n == 0 ? 0 : sum / n;
  }

  void
  expect_names(const Mesh &mesh, const std::set<std::string> &expected)
  {
    std::set<std::string> names;
    for (const auto &[name, id] : mesh.boundary_ids)
      names.insert(name);
    EXPECT_EQ(names, expected);
  }

  /// Every vertex of boundary `name` satisfies `on`, and its faces add up to `length`.
  void
  expect_boundary(const Mesh                                  &mesh,
                  const std::string                           &name,
                  double                                       length,
                  const std::function<bool(const Point<2> &)> &on,
                  double                                       relative_tolerance = 1e-12)
  {
    SCOPED_TRACE("boundary " + name);
    const auto id = mesh.id(name, "test");
    EXPECT_NEAR(boundary_lengths(mesh.triangulation)[id], length, relative_tolerance * length);
    for (const auto &cell : mesh.triangulation.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary() && face->boundary_id() == id)
          {
            for (unsigned int v = 0; v < 2; ++v)
              EXPECT_TRUE(on(face->vertex(v))) << face->vertex(v);
          }
  }

  std::function<bool(const Point<2> &)>
  on_x(double x, double y_min, double y_max)
  {
    return [=](const Point<2> &p) {
      return std::abs(p[0] - x) < 1e-12 && p[1] > y_min - 1e-12 && p[1] < y_max + 1e-12;
    };
  }

  std::function<bool(const Point<2> &)>
  on_y(double y, double x_min, double x_max)
  {
    return [=](const Point<2> &p) {
      return std::abs(p[1] - y) < 1e-12 && p[0] > x_min - 1e-12 && p[0] < x_max + 1e-12;
    };
  }

  void
  expect_area(const Mesh &mesh, double area, double relative_tolerance = 1e-12)
  {
    EXPECT_NEAR(area_from_measures(mesh.triangulation), area, relative_tolerance * area);
    EXPECT_NEAR(area_from_quadrature(mesh.triangulation), area, relative_tolerance * area);
    for (const auto &cell : mesh.triangulation.active_cell_iterators())
      ASSERT_GT(cell->measure(), 0) << cell->center();
  }

  /// deal.II's own reader, given the same file, assigns every boundary face the same id.
  void
  expect_gridin_agrees(const Mesh &mesh, const std::string &msh_path)
  {
    Triangulation<2> tria;
    GridIn<2>        grid_in(tria);
    grid_in.read_msh(msh_path);
    ASSERT_EQ(tria.n_active_cells(), mesh.triangulation.n_active_cells());

    const auto key = [](const Point<2> &p) {
      return std::make_pair(std::llround(p[0] * 1e9), std::llround(p[1] * 1e9));
    };
    std::map<std::pair<long long, long long>, types::boundary_id> ids;
    for (const auto &cell : mesh.triangulation.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary())
          ids[key(face->center())] = face->boundary_id();
    unsigned int n_faces = 0;
    for (const auto &cell : tria.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary())
          {
            ++n_faces;
            const auto it = ids.find(key(face->center()));
            ASSERT_NE(it, ids.end()) << face->center();
            EXPECT_EQ(face->boundary_id(), it->second) << face->center();
          }
    EXPECT_EQ(n_faces, ids.size());
  }

  /// The message of the InputError `f` throws; a test failure if it throws nothing.
  std::string
  input_error(const std::function<void()> &f)
  {
    try
      {
        f();
      }
    catch (const InputError &e)
      {
        return e.what();
      }
    ADD_FAILURE() << "no InputError thrown";
    return "";
  }

  void
  expect_contains(const std::string &message, std::initializer_list<std::string> parts)
  {
    for (const auto &part : parts)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }

  /// A Gmsh MSH 2.2 file on the unit square: nodes 1-4 counterclockwise from the origin.
  void
  write_unit_square_msh2(const std::string &file,
                         const std::string &names,
                         const std::string &elements)
  {
    std::ofstream out(file);
    out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
        << "$PhysicalNames\n"
        << names << "$EndPhysicalNames\n"
        << "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n"
        << "$Elements\n"
        << elements << "$EndElements\n";
  }

  // Element lines: number, type (1 line, 2 triangle, 3 quad), 2 tags (physical, elementary), nodes.
  const std::string square_names = "3\n1 1 \"wall\"\n1 2 \"lid\"\n2 3 \"domain\"\n";
  const std::string square_lines =
    "1 1 2 1 11 1 2\n2 1 2 1 12 2 3\n3 1 2 2 13 3 4\n4 1 2 1 14 4 1\n";
  // The second triangle is clockwise.
  const std::string square_triangles = "5 2 2 3 21 1 2 3\n6 2 2 3 21 1 4 3\n";

  TEST_F(Geometry, ChannelHasAreaBoundariesAndLengths)
  {
    const double length = 2, width = 1;
    Mesh         mesh;
    granflow::geometry::make_channel(mesh, length, width, 0.1, path("channel.msh"), "case.prm");

    EXPECT_TRUE(fs::is_regular_file(path("channel.msh")));
    EXPECT_FALSE(fs::exists(path("channel.partial.msh")));
    expect_area(mesh, length * width);
    expect_names(mesh, {"bottom", "top", "inlet", "outlet"});
    expect_boundary(mesh, "bottom", length, on_y(-width / 2, -length, 0));
    expect_boundary(mesh, "top", length, on_y(width / 2, -length, 0));
    expect_boundary(mesh, "inlet", width, on_x(-length, -width / 2, width / 2));
    expect_boundary(mesh, "outlet", width, on_x(0, -width / 2, width / 2));
    expect_gridin_agrees(mesh, path("channel.msh"));
  }

  TEST_F(Geometry, SquarePatchHasAreaBoundariesAndLengths)
  {
    Mesh mesh;
    granflow::geometry::make_square_patch(mesh, 1, 0.1, path("patch.msh"), "case.prm");

    expect_area(mesh, 1);
    expect_names(mesh, {"bed", "surface", "upstream", "downstream"});
    expect_boundary(mesh, "bed", 1, on_y(0, 0, 1));
    expect_boundary(mesh, "surface", 1, on_y(1, 0, 1));
    expect_boundary(mesh, "upstream", 1, on_x(0, 0, 1));
    expect_boundary(mesh, "downstream", 1, on_x(1, 0, 1));
    expect_gridin_agrees(mesh, path("patch.msh"));
  }

  TEST_F(Geometry, HalfSiloWithExtensionHasAreaBoundariesAndLengths)
  {
    const double W = 4, H = 3, D = 1, extension = 0.5;
    Mesh         mesh;
    granflow::geometry::make_half_silo(
      mesh, W, H, D, extension, 0.25, path("silo.msh"), "case.prm");

    expect_area(mesh, W * H + D / 2 * extension);
    expect_names(mesh, {"axis", "wall", "bottom", "top", "outlet", "outlet_wall"});
    expect_boundary(mesh, "axis", H + extension, on_x(0, -extension, H));
    expect_boundary(mesh, "wall", H, on_x(W, 0, H));
    expect_boundary(mesh, "bottom", W - D / 2, on_y(0, D / 2, W));
    expect_boundary(mesh, "top", W, on_y(H, 0, W));
    expect_boundary(mesh, "outlet", D / 2, on_y(-extension, 0, D / 2));
    expect_boundary(mesh, "outlet_wall", extension, on_x(D / 2, -extension, 0));
    expect_gridin_agrees(mesh, path("silo.msh"));

    // The aperture is resolved by interior edges: the discharge rate is measured there.
    double aperture = 0;
    for (const auto &cell : mesh.triangulation.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (on_y(0, 0, D / 2)(face->vertex(0)) && on_y(0, 0, D / 2)(face->vertex(1)))
          aperture += face->measure();
    EXPECT_NEAR(aperture, 2 * D / 2, 1e-12); // each interior edge is seen from both sides
  }

  TEST_F(Geometry, HalfSiloWithoutExtensionHasTheApertureAsOutlet)
  {
    const double W = 4, H = 3, D = 1;
    Mesh         mesh;
    granflow::geometry::make_half_silo(mesh, W, H, D, 0, 0.25, path("silo.msh"), "case.prm");

    expect_area(mesh, W * H);
    expect_names(mesh, {"axis", "wall", "bottom", "top", "outlet"});
    expect_boundary(mesh, "axis", H, on_x(0, 0, H));
    expect_boundary(mesh, "bottom", W - D / 2, on_y(0, D / 2, W));
    expect_boundary(mesh, "outlet", D / 2, on_y(0, 0, D / 2));
  }

  TEST_F(Geometry, CylinderChannelHasAreaBoundariesAndRefinedCylinder)
  {
    const double length = 4, width = 1, D = 0.25, h = 0.1;
    Mesh         mesh;
    granflow::geometry::make_cylinder_channel(
      mesh, length, width, D, h, path("cyl.msh"), "case.prm");

    // The cylinder is an inscribed polygon: the hole is slightly too small.
    const double exact_area = length * width - pi * D * D / 4;
    EXPECT_NEAR(area_from_measures(mesh.triangulation), exact_area, 0.01 * exact_area);
    EXPECT_NEAR(area_from_quadrature(mesh.triangulation),
                area_from_measures(mesh.triangulation),
                1e-12 * exact_area);
    EXPECT_GT(area_from_measures(mesh.triangulation), exact_area);

    expect_names(mesh, {"walls", "cylinder", "inlet", "outlet"});
    expect_boundary(mesh, "walls", 2 * length, [&](const Point<2> &p) {
      return std::abs(std::abs(p[1]) - width / 2) < 1e-12;
    });
    expect_boundary(mesh, "inlet", width, on_x(-length / 2, -width / 2, width / 2));
    expect_boundary(mesh, "outlet", width, on_x(length / 2, -width / 2, width / 2));
    expect_boundary(
      mesh,
      "cylinder",
      pi * D,
      [&](const Point<2> &p) { return std::abs(p.norm() - D / 2) < 1e-9; },
      0.01);

    // Size h/3 on the cylinder, h on the walls.
    const double cylinder_edge = mean_edge_length(mesh.triangulation, mesh.id("cylinder", "test"));
    const double wall_edge     = mean_edge_length(mesh.triangulation, mesh.id("walls", "test"));
    EXPECT_NEAR(cylinder_edge, h / 3, 0.25 * h / 3);
    EXPECT_NEAR(wall_edge, h, 0.25 * h);
    expect_gridin_agrees(mesh, path("cyl.msh"));
  }

  TEST_F(Geometry, HalvingTheMeshSizeQuadruplesTheCells)
  {
    Mesh coarse, fine;
    granflow::geometry::make_channel(coarse, 2, 1, 0.1, path("coarse.msh"), "case.prm");
    granflow::geometry::make_channel(fine, 2, 1, 0.05, path("fine.msh"), "case.prm");
    const double ratio =
      double(fine.triangulation.n_active_cells()) / double(coarse.triangulation.n_active_cells());
    EXPECT_GT(ratio, 3.4);
    EXPECT_LT(ratio, 4.6);
  }

  TEST_F(Geometry, GlobalRefinementQuadruplesCellsAndKeepsBoundaries)
  {
    const double W = 4, H = 3, D = 1, extension = 0.5;
    Mesh         mesh;
    granflow::geometry::make_half_silo(mesh, W, H, D, extension, 0.5, path("silo.msh"), "case.prm");
    const auto n_cells = mesh.triangulation.n_active_cells();
    const auto lengths = boundary_lengths(mesh.triangulation);

    mesh.triangulation.refine_global(1);

    EXPECT_EQ(mesh.triangulation.n_active_cells(), 4 * n_cells);
    expect_area(mesh, W * H + D / 2 * extension);
    const auto refined_lengths = boundary_lengths(mesh.triangulation);
    ASSERT_EQ(refined_lengths.size(), lengths.size());
    for (const auto &[id, length] : lengths)
      EXPECT_NEAR(refined_lengths.at(id), length, 1e-12 * length) << "boundary id " << id;
    expect_boundary(mesh, "outlet_wall", extension, on_x(D / 2, -extension, 0));
  }

  TEST_F(Geometry, SimplexElementsWorkOnTheRefinedMesh)
  {
    const double length = 2, width = 1;
    Mesh         mesh;
    granflow::geometry::make_channel(mesh, length, width, 0.25, path("channel.msh"), "case.prm");
    mesh.triangulation.refine_global(1);
    const auto &tria = mesh.triangulation;

    // Euler on a disc: V - E + T = 1.
    const auto n_edges = tria.n_used_vertices() + tria.n_active_cells() - 1;

    DoFHandler<2>        dof_p2(tria);
    const FE_SimplexP<2> p2(2);
    dof_p2.distribute_dofs(p2);
    EXPECT_EQ(dof_p2.n_dofs(), tria.n_used_vertices() + n_edges);

    DoFHandler<2>          dof_dg(tria);
    const FE_SimplexDGP<2> dgp1(1);
    dof_dg.distribute_dofs(dgp1);
    EXPECT_EQ(dof_dg.n_dofs(), 3 * tria.n_active_cells());

    // x^2 + xy is in P2: its interpolant integrates exactly, to width * length^3 / 3.
    const MappingFE<2> mapping(FE_SimplexP<2>(1));
    Vector<double>     u(dof_p2.n_dofs());
    VectorTools::interpolate(mapping,
                             dof_p2,
                             ScalarFunctionFromFunctionObject<2>(
                               [](const Point<2> &p) { return p[0] * p[0] + p[0] * p[1]; }),
                             u);
    const QGaussSimplex<2> quadrature(3);
    FEValues<2>            fe_values(mapping, p2, quadrature, update_values | update_JxW_values);
    std::vector<double>    values(quadrature.size());
    double                 integral = 0;
    for (const auto &cell : dof_p2.active_cell_iterators())
      {
        fe_values.reinit(cell);
        fe_values.get_function_values(u, values);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          integral += values[q] * fe_values.JxW(q);
      }
    EXPECT_NEAR(integral, width * length * length * length / 3, 1e-12);
  }

  TEST_F(Geometry, ReadsAUserMeshWithNamedCurvesAndReorientsTriangles)
  {
    write_unit_square_msh2(path("square.msh"),
                           square_names,
                           "6\n" + square_lines + square_triangles);
    Mesh mesh;
    granflow::geometry::read_mesh_file(mesh, path("square.msh"), "case.prm");

    EXPECT_EQ(mesh.triangulation.n_active_cells(), 2u);
    expect_area(mesh, 1);
    expect_names(mesh, {"wall", "lid"});
    // Physical tags become the ids, as deal.II's GridIn assigns them.
    EXPECT_EQ(mesh.id("wall", "test"), 1u);
    EXPECT_EQ(mesh.id("lid", "test"), 2u);
    expect_boundary(mesh, "wall", 3, [](const Point<2> &p) {
      return p[0] == 0 || p[0] == 1 || p[1] == 0;
    });
    expect_boundary(mesh, "lid", 1, on_y(1, 0, 1));
  }

  TEST_F(Geometry, TriangleInTwoPhysicalSurfacesIsOneCell)
  {
    // MSH 2 writes a triangle once per physical surface: here triangle 1-2-3 is also in a tagged
    // sub-region "lower". Read as two cells, the copies would hide the boundary edges 1-2 and 2-3
    // between them (the wall would lose them), and the area would be 1.5.
    write_unit_square_msh2(path("sub.msh"),
                           "4\n1 1 \"wall\"\n1 2 \"lid\"\n2 3 \"domain\"\n2 4 \"lower\"\n",
                           "7\n" + square_lines + square_triangles + "7 2 2 4 21 1 2 3\n");
    Mesh mesh;
    granflow::geometry::read_mesh_file(mesh, path("sub.msh"), "case.prm");
    EXPECT_EQ(mesh.triangulation.n_active_cells(), 2u);
    expect_area(mesh, 1);
    expect_boundary(mesh, "wall", 3,
                    [](const Point<2> &p) { return p[0] == 0 || p[0] == 1 || p[1] == 0; });
  }

  TEST_F(Geometry, NonConformingInterfaceIsRejected)
  {
    // Two unit squares side by side, meshed apart: the right one has its own nodes 5 and 8 on
    // x = 1 and a node 9 at (1, 0.5) that the left one lacks. Read as it is, the interface would
    // be a crack; the check names where the edges overlap.
    {
      std::ofstream out(path("nonconforming.msh"));
      out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
          << "$PhysicalNames\n2\n1 1 \"wall\"\n2 2 \"domain\"\n$EndPhysicalNames\n"
          << "$Nodes\n9\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 1 0 0\n6 2 0 0\n7 2 1 0\n"
          << "8 1 1 0\n9 1 0.5 0\n$EndNodes\n"
          << "$Elements\n11\n"
          << "1 1 2 1 1 1 2\n2 1 2 1 1 3 4\n3 1 2 1 1 4 1\n4 1 2 1 1 5 6\n5 1 2 1 1 6 7\n"
          << "6 1 2 1 1 7 8\n"
          << "7 2 2 2 2 1 2 3\n8 2 2 2 2 1 3 4\n9 2 2 2 3 5 6 9\n10 2 2 2 3 6 7 9\n"
          << "11 2 2 2 3 7 8 9\n$EndElements\n";
    }
    Mesh mesh;
    expect_contains(input_error([&] {
                      granflow::geometry::read_mesh_file(mesh, path("nonconforming.msh"),
                                                         "case.prm");
                    }),
                    {"case.prm", "non-conforming interface at (1, 0.25)"});
  }

  TEST_F(Geometry, RoundTripThroughTheWrittenFile)
  {
    Mesh generated, read;
    granflow::geometry::make_half_silo(generated, 4, 3, 1, 0.5, 0.3, path("silo.msh"), "case.prm");
    granflow::geometry::read_mesh_file(read, path("silo.msh"), "case.prm");
    EXPECT_EQ(read.triangulation.n_active_cells(), generated.triangulation.n_active_cells());
    EXPECT_EQ(read.boundary_ids, generated.boundary_ids);
    EXPECT_EQ(boundary_lengths(read.triangulation).size(), 6u);
  }

  TEST_F(Geometry, BadMeshSizeNamesTheEntry)
  {
    for (const double h : {0., -0.1, std::numeric_limits<double>::quiet_NaN(), 1e-6})
      {
        SCOPED_TRACE("h = " + std::to_string(h));
        Mesh mesh;
        expect_contains(
          input_error(
            [&] { granflow::geometry::make_channel(mesh, 2, 1, h, path("c.msh"), "case.prm"); }),
          {"case.prm", "Geometry/Mesh size", "expected a number in"});
      }
  }

  TEST_F(Geometry, BadLengthsNameTheEntry)
  {
    using namespace granflow::geometry;
    Mesh       m;
    const auto f = path("m.msh");
    expect_contains(input_error([&] { make_channel(m, 2, -1, 0.1, f, "case.prm"); }),
                    {"case.prm", "Geometry/Channel width", "(0, inf)"});
    expect_contains(input_error([&] { make_square_patch(m, 0, 0.1, f, "case.prm"); }),
                    {"Geometry/Patch size", "(0, inf)"});
    expect_contains(input_error([&] { make_cylinder_channel(m, 4, 1, 1, 0.1, f, "case.prm"); }),
                    {"Geometry/Cylinder diameter", "(0, width = 1)"});
    expect_contains(input_error([&] { make_half_silo(m, 1, 2, 2, 0, 0.1, f, "case.prm"); }),
                    {"Geometry/Aperture", "(0, 2 W = 2)"});
    expect_contains(input_error([&] { make_half_silo(m, 1, 2, 0.5, -1, 0.1, f, "case.prm"); }),
                    {"Geometry/Outlet extension", "[0, inf)"});
    expect_contains(input_error([&] { make_half_silo(m, 1, -2, 0.5, 0, 0.1, f, "case.prm"); }),
                    {"Geometry/Silo height"});
  }

  TEST_F(Geometry, UnwritableMeshPathIsReported)
  {
    Mesh       mesh;
    const auto f = path("missing_dir/channel.msh");
    expect_contains(input_error(
                      [&] { granflow::geometry::make_channel(mesh, 2, 1, 0.1, f, "case.prm"); }),
                    {"case.prm", f});
  }

  TEST_F(Geometry, MissingMeshFileNamesTheFile)
  {
    Mesh       mesh;
    const auto f = path("nowhere.msh");
    expect_contains(input_error([&] { granflow::geometry::read_mesh_file(mesh, f, "case.prm"); }),
                    {"case.prm", "Geometry/Mesh file", f});
  }

  TEST_F(Geometry, FileThatIsNotAMeshIsNamedAsSuch)
  {
    // A .geo script given as the mesh: said to be no mesh, not "no triangles" from deep in Gmsh.
    {
      std::ofstream out(path("square.geo"));
      out << "Point(1) = {0, 0, 0};\n";
    }
    Mesh mesh;
    expect_contains(input_error([&] {
                      granflow::geometry::read_mesh_file(mesh, path("square.geo"), "case.prm");
                    }),
                    {"case.prm", "Geometry/Mesh file", "not a Gmsh mesh file"});
    expect_contains(
        input_error([&] { granflow::geometry::read_mesh_file(mesh, path(""), "case.prm"); }),
        {"case.prm", "is a directory"});
  }

  TEST_F(Geometry, MeshWithoutTrianglesIsRejected)
  {
    Mesh mesh;
    write_unit_square_msh2(path("lines.msh"), square_names, "4\n" + square_lines);
    expect_contains(input_error([&] {
                      granflow::geometry::read_mesh_file(mesh, path("lines.msh"), "case.prm");
                    }),
                    {"case.prm", "lines.msh", "no triangles"});

    write_unit_square_msh2(path("quads.msh"),
                           square_names,
                           "5\n" + square_lines + "5 3 2 3 21 1 2 3 4\n");
    expect_contains(input_error([&] {
                      granflow::geometry::read_mesh_file(mesh, path("quads.msh"), "case.prm");
                    }),
                    {"quads.msh", "expected only 3-node triangles"});
  }

  TEST_F(Geometry, BoundaryEdgeWithoutNameIsRejected)
  {
    Mesh mesh;
    // The lid (element 3) is left out of every physical curve.
    write_unit_square_msh2(path("open.msh"),
                           square_names,
                           "5\n1 1 2 1 11 1 2\n2 1 2 1 12 2 3\n4 1 2 1 14 4 1\n" +
                             square_triangles);
    expect_contains(input_error([&] {
                      granflow::geometry::read_mesh_file(mesh, path("open.msh"), "case.prm");
                    }),
                    {"open.msh", "1 boundary edges", "(0.5, 1)", "no named physical curve"});
  }

  // A profile line across the cylinder of Fig. 12: the points in the hole are left out, the others
  // carry the field's values (a P2 field that interpolates x + 2 y exactly).
  TEST_F(Geometry, ProfileAcrossTheCylinderLeavesOutThePointsInTheHole)
  {
    const double length = 4, width = 1, D = 0.25, h = 0.1;
    Mesh         mesh;
    granflow::geometry::make_cylinder_channel(mesh, length, width, D, h, path("cyl.msh"),
                                              "case.prm");
    const MappingFE<2> mapping(FE_SimplexP<2>(1));
    const FESystem<2>  fe(FE_SimplexP<2>(2), 2);
    DoFHandler<2>      dof(mesh.triangulation);
    dof.distribute_dofs(fe);
    Vector<double> u(dof.n_dofs());
    VectorTools::interpolate(
        mapping, dof,
        FunctionFromFunctionObjects<2>({[](const Point<2> &p) { return p[0] + 2 * p[1]; },
                                        [](const Point<2> &) { return 0.; }}),
        u);
    const unsigned int n = 101;
    const auto         samples =
        granflow::postprocess::sample_line(mapping, dof, u, Point<2>(0, -0.5), Point<2>(0, 0.5), n);
    // Points 0.01 apart; the inscribed polygon's hole is at most D/2 wide on each side of y = 0.
    EXPECT_GE(samples.points.size(), n - 26);
    EXPECT_LE(samples.points.size(), n - 20);
    for (std::size_t k = 0; k < samples.points.size(); ++k)
      {
        EXPECT_GE(std::abs(samples.points[k][1]), D / 2 * std::cos(pi / 8) - 1e-12);
        EXPECT_NEAR(samples.values[k][0], 2 * samples.points[k][1], 1e-12);
      }
  }

  TEST_F(Geometry, UnknownBoundaryNameListsTheKnownOnes)
  {
    Mesh mesh;
    granflow::geometry::make_square_patch(mesh, 1, 0.5, path("patch.msh"), "case.prm");
    expect_contains(
      input_error([&] { mesh.id("wall", "cases/silo.prm"); }),
      {"cases/silo.prm", "'wall'", "'bed'", "'downstream'", "'surface'", "'upstream'"});
  }

  // A user's mesh may name a boundary with a character the case file's lists use as a separator
  // (docs/dp.md, "A user mesh"): the error for the name the user tried says which names cannot be
  // written, and why.
  TEST_F(Geometry, UnknownBoundaryNameSaysWhichMeshNamesCannotBeWritten)
  {
    Mesh mesh;
    mesh.boundary_ids = {{"inlet", 1}, {"wall (left)", 2}, {"a,b", 3}, {"top:1", 4},
                         {" bed", 5},  {"c#1", 6},         {"", 7}};
    expect_contains(input_error([&] { mesh.id("wall", "cases/mine.prm", "No-slip"); }),
                    {"cases/mine.prm", "No-slip", "'wall'",
                     "'', ' bed', 'a,b', 'c#1', 'top:1', 'wall (left)' cannot be named",
                     "rename the physical curve"});
    mesh.boundary_ids = {{"inlet", 1}, {"outlet", 2}};
    EXPECT_EQ(input_error([&] { mesh.id("wall", "cases/mine.prm"); }).find("cannot be named"),
              std::string::npos);
  }
} // namespace
