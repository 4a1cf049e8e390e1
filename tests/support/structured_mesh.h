// Test support: a structured triangle mesh of a (possibly rotated) rectangle as a Gmsh 2.2 file,
// for cases that read their mesh from a file.
#pragma once

#include <cmath>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <map>
#include <sstream>
#include <string>

namespace granflow::test
{
  /// [x0, x1] x [y0, y1] in nx x ny squares, each cut along its diagonal, rotated by `angle`
  /// (radians, counterclockwise about the origin). Physical curves "bottom" (y = y0; its i-th
  /// segment named bottom_name(i) if given), "top", "inlet" (x = x0), "outlet"; surface "domain".
  /// `shear`, if given, moves each node (x, y) to (x, y + shear(x)) before the rotation;
  /// `end_shear` to (x + end_shear(y), y).
  inline void
  write_rectangle_msh(const std::string &file, const int nx, const int ny, const double x0,
                      const double x1, const double y0, const double y1, const double angle = 0.,
                      const std::function<std::string(int)> &bottom_name = {},
                      const std::function<double(double)>   &shear       = {},
                      const std::function<double(double)>   &end_shear   = {})
  {
    std::map<std::string, int> physical; // name -> tag
    const auto                 tag = [&](const std::string &name) {
      return physical.emplace(name, static_cast<int>(physical.size()) + 1).first->second;
    };
    std::ostringstream elements;
    int                n_elements = 0;
    const auto         node       = [&](int i, int j) { return 1 + i + (nx + 1) * j; };
    // element: type (1 line, 2 triangle), 2 tags (physical, elementary), nodes
    const auto element = [&](int type, const std::string &name, std::initializer_list<int> nodes) {
      const int t = tag(name);
      elements << ++n_elements << " " << type << " 2 " << t << " " << t;
      for (const int n : nodes)
        elements << " " << n;
      elements << "\n";
    };
    for (int i = 0; i < nx; ++i)
      {
        element(1, bottom_name ? bottom_name(i) : "bottom", {node(i, 0), node(i + 1, 0)});
        element(1, "top", {node(i, ny), node(i + 1, ny)});
      }
    for (int j = 0; j < ny; ++j)
      {
        element(1, "inlet", {node(0, j), node(0, j + 1)});
        element(1, "outlet", {node(nx, j), node(nx, j + 1)});
      }
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        {
          element(2, "domain", {node(i, j), node(i + 1, j), node(i + 1, j + 1)});
          element(2, "domain", {node(i, j), node(i + 1, j + 1), node(i, j + 1)});
        }

    std::ofstream msh(file);
    msh.precision(17);
    msh << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n" << physical.size() << "\n";
    for (const auto &[name, t] : physical)
      msh << (name == "domain" ? 2 : 1) << " " << t << " \"" << name << "\"\n";
    msh << "$EndPhysicalNames\n$Nodes\n" << (nx + 1) * (ny + 1) << "\n";
    const double c = std::cos(angle), s = std::sin(angle);
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        {
          const double x_grid = x0 + (x1 - x0) * i / nx, y_grid = y0 + (y1 - y0) * j / ny;
          const double x = x_grid + (end_shear ? end_shear(y_grid) : 0.),
                       y = y_grid + (shear ? shear(x_grid) : 0.);
          msh << node(i, j) << " " << c * x - s * y << " " << s * x + c * y << " 0\n";
        }
    msh << "$EndNodes\n$Elements\n" << n_elements << "\n" << elements.str() << "$EndElements\n";
  }

  /// The triangle with apex (0, 0) and top corners (-a, 1), (a, 1): row j (y = j / n) has j + 1
  /// nodes; physical curves "left", "right", "top", surface "domain".
  inline void
  write_wedge_msh(const std::string &file, const int n, const double a)
  {
    const auto         node = [](int j, int k) { return 1 + j * (j + 1) / 2 + k; };
    std::ostringstream elements;
    int                count   = 0;
    const auto         element = [&](int type, int tag, std::initializer_list<int> nodes) {
      elements << ++count << " " << type << " 2 " << tag << " " << tag;
      for (const int v : nodes)
        elements << " " << v;
      elements << "\n";
    };
    for (int j = 0; j < n; ++j)
      {
        element(1, 1, {node(j, 0), node(j + 1, 0)});
        element(1, 2, {node(j, j), node(j + 1, j + 1)});
        element(1, 3, {node(n, j), node(n, j + 1)});
        for (int k = 0; k <= j; ++k)
          element(2, 4, {node(j, k), node(j + 1, k), node(j + 1, k + 1)});
        for (int k = 0; k < j; ++k)
          element(2, 4, {node(j, k), node(j + 1, k + 1), node(j, k + 1)});
      }
    std::ofstream msh(file);
    msh.precision(17);
    msh << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n4\n1 1 \"left\"\n1 2 "
           "\"right\"\n1 3 \"top\"\n2 4 \"domain\"\n$EndPhysicalNames\n$Nodes\n"
        << (n + 1) * (n + 2) / 2 << "\n";
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= j; ++k)
        {
          const double y = double(j) / n, x = j == 0 ? 0. : a * y * (2. * k / j - 1.);
          msh << node(j, k) << " " << x << " " << y << " 0\n";
        }
    msh << "$EndNodes\n$Elements\n" << count << "\n" << elements.str() << "$EndElements\n";
  }
} // namespace granflow::test
