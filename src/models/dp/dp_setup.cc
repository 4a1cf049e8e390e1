// The dp Problem's setup: mesh, dofs, velocity conditions and loads, and the checks of the input
// that need the mesh (rigid motions left free, inflow into a closed domain). Daviet 4.3, 4.4.4.
#include "models/dp/dp_problem.h"

#include <deal.II/base/function.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/numerics/vector_tools.h>
#include <filesystem>

namespace granflow::dp::detail
{
  void
  Problem::make_mesh()
  {
    const auto &g   = prm.geometry;
    const auto  msh = out.file("mesh.msh");
    const auto &f   = prm.case_file;
    for (const auto &message : prm.ignored_geometry_entries())
      report.warn(message);
    // A fine mesh (1.5 million triangles at Mesh size 0.01 on the silo) took minutes without a
    // line on the console.
    mesh.before_meshing = [&](const double triangles) {
      if (triangles > 2e5)
        {
          std::ostringstream s;
          s << std::setprecision(2) << "meshing the " << g.shape << ": about " << triangles
            << " triangles at Geometry/Mesh size = " << g.mesh_size << "\n";
          log.print(s.str());
        }
    };
    if (g.shape == "channel")
      geometry::make_channel(mesh, g.channel_length, g.channel_width, g.mesh_size, msh, f);
    else if (g.shape == "square patch")
      geometry::make_square_patch(mesh, g.patch_size, g.mesh_size, msh, f);
    else if (g.shape == "half silo")
      geometry::make_half_silo(mesh, g.silo_width, g.silo_height, g.aperture, g.outlet_extension,
                               g.mesh_size, msh, f);
    else if (g.shape == "cylinder channel")
      geometry::make_cylinder_channel(mesh, g.channel_length, g.channel_width, g.cylinder_diameter,
                                      g.mesh_size, msh, f);
    else
      {
        geometry::read_mesh_file(mesh, g.mesh_file, f);
        // The output directory keeps the mesh the run read, as for the generated shapes (before
        // Global refinements, which parameters.prm repeats).
        std::error_code ec;
        std::filesystem::copy_file(g.mesh_file, msh,
                                   std::filesystem::copy_options::overwrite_existing, ec);
        if (ec)
          report.warn("the mesh file " + g.mesh_file +
                      " could not be copied into the output directory (" + ec.message() +
                      "); the run goes on with the mesh read from it");
      }
    if (g.refinements > 0)
      {
        // New vertices on the cylinder go onto the circle, not onto the chords of the coarse
        // mesh (the generator centres the cylinder at the origin).
        if (g.shape == "cylinder channel")
          {
            const auto cylinder = mesh.id("cylinder", f);
            for (const auto &face : mesh.triangulation.active_face_iterators())
              if (face->at_boundary() && face->boundary_id() == cylinder)
                face->set_manifold_id(1);
            mesh.triangulation.set_manifold(1, SphericalManifold<dim>(Point<dim>()));
          }
        // Each refinement quadruples the triangles; the generators' bound of 1e7 holds for the
        // refined mesh too.
        const double triangles = mesh.triangulation.n_active_cells() * std::pow(4., g.refinements);
        if (triangles > 1e7)
          {
            std::ostringstream s;
            s << "= " << g.refinements << " gives " << triangles << " triangles (from "
              << mesh.triangulation.n_active_cells() << "): expected at most 1e7";
            throw InputError(prm.case_file, "Geometry/Global refinements", s.str());
          }
        mesh.triangulation.refine_global(g.refinements);
      }
  }

  void
  Problem::setup()
  {
    dof_u.reinit(mesh.triangulation);
    dof_u.distribute_dofs(fe_u);
    dof_s.reinit(mesh.triangulation);
    dof_s.distribute_dofs(fe_s);
    apply_boundary_conditions();
    number_free_dofs();
    n_points = p1d ? mesh.triangulation.n_active_cells() * 3 : dof_s.n_dofs();
    u.reinit(dof_u.n_dofs());
    // The profile line must cross the domain: checked now, not after the solve. The default line
    // (the mesh's vertical middle line, which a U-shaped mesh or one with a hole may miss) is
    // not refused, only left out with a warning: the user did not ask for it.
    const auto [a, b] = profile_line();
    if (postprocess::sample_line(mapping, dof_u, u, a, b, prm.output.profile_points).points.size() <
        2)
      {
        if (prm.output.profile_start.empty())
          {
            std::ostringstream w;
            w << "no profiles/velocity.csv: the mesh's vertical middle line, (" << a[0] << ", "
              << a[1] << ") to (" << b[0] << ", " << b[1] << "), has fewer than 2 of its "
              << prm.output.profile_points
              << " points in the mesh; set Output/Profile start and end to a line across the "
                 "domain";
            report.warn(w.str());
          }
        else
          throw InputError(prm.case_file, "Output/Profile start",
                           "'" + prm.output.profile_start + "' to Output/Profile end '" +
                               prm.output.profile_end + "': fewer than 2 of the line's " +
                               std::to_string(prm.output.profile_points) +
                               " points lie in the mesh: expected a line across the domain");
      }
    else
      profile.emplace(a, b);

    std::ostringstream s;
    s << "Mesh: " << mesh.triangulation.n_active_cells() << " triangles, "
      << mesh.triangulation.n_vertices() << " vertices; velocity P2: " << dof_u.n_dofs()
      << " dofs (" << n_free << " free); stress " << prm.solver.stress_element << ": " << n_points
      << " constraint points\n";
    log.print(s.str());

    note_unconditioned_and_unresolved_boundaries();
    prm.require_reference_boundaries();
    // Only the direction of gravity enters (23): the body force is rho g, in units of rho g.
    if (const Point<dim> g = parse_point(prm.gravity_direction, prm.case_file, "Gravity direction");
        std::abs(g.norm() - 1.) > 1e-12)
      {
        std::ostringstream   note;
        const Tensor<1, dim> e = prm.e_g();
        note << "dp: note: Gravity direction (" << g[0] << ", " << g[1] << ") has length "
             << g.norm() << "; only its direction (" << e[0] << ", " << e[1]
             << ") is used: the body force is rho g, the unit of (23)\n";
        log.print(note.str());
      }
  }

  void
  Problem::apply_boundary_conditions()
  {
    const auto &bc = prm.boundaries;
    // A name in two velocity conditions is a contradiction or a typo.
    const auto velocities =
        parse_named_velocities(bc.velocity, prm.case_file, "Boundary conditions/Velocity");
    std::vector<std::pair<std::string, const char *>> named; // (boundary, entry)
    for (const auto &[list, entry] : bc.velocity_conditions())
      for (const std::string &name : split_list(*list))
        named.emplace_back(name, entry);
    for (const auto &[name, value] : velocities)
      named.emplace_back(name, "Velocity");
    std::map<types::boundary_id, const char *> condition_of;
    for (const auto &[name, entry] : named)
      if (const auto [it, fresh] = condition_of.emplace(
              mesh.id(name, prm.case_file, std::string("Boundary conditions/") + entry), entry);
          !fresh)
        throw InputError(prm.case_file, std::string("Boundary conditions/") + entry,
                         "names '" + name + "', which is also in Boundary conditions/" +
                             it->second + ": expected one velocity condition per boundary");
    // The normal flux integral u_D . n that boundary `id`'s velocity condition prescribes, if
    // it holds u . n on every face: No-slip, Velocity and Zero normal velocity do; Zero x- or
    // y-velocity only where the boundary is normal to that axis (x = const or y = const).
    struct NormalFlux
    {
      double flux;
      bool   zero; // |flux| at most 1e-12 of |u_D| times the boundary's length
    };
    const auto prescribed_normal_flux =
        [&](const types::boundary_id id,
            const std::string       &condition) -> std::optional<NormalFlux> {
      Tensor<1, dim> u_D;
      for (const auto &[name, value] : velocities)
        if (mesh.id(name, prm.case_file) == id && condition == "Velocity")
          u_D = value;
      const int fixed_axis = condition == "Zero x-velocity"   ? 0
                             : condition == "Zero y-velocity" ? 1
                                                              : -1;
      if (condition == "Zero tangential velocity")
        return std::nullopt;
      const QGauss<dim - 1> face_quadrature(2);
      FEFaceValues<dim>     fvf(mapping, fe_u, face_quadrature,
                                update_normal_vectors | update_JxW_values);
      double                flux = 0., length = 0.;
      bool                  holds = true;
      for_each_face_on(dof_u, id, fvf, [&](const auto &) {
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          {
            const Tensor<1, dim> n = fvf.normal_vector(q);
            if (fixed_axis >= 0 && std::abs(n[1 - fixed_axis]) > 1e-9)
              holds = false;
            flux += (u_D * n) * fvf.JxW(q);
            length += fvf.JxW(q);
          }
      });
      if (!holds)
        return std::nullopt;
      return NormalFlux{flux, std::abs(flux) <= 1e-12 * u_D.norm() * length};
    };
    // u = value on boundary `name`, in the components of `mask`. A dof already fixed keeps its
    // value: the homogeneous conditions come first, so a moving lid's end nodes on no-slip
    // walls stay at rest, and of two Velocity boundaries the one listed first wins.
    const auto add = [&](const std::string &name, const char *entry, const ComponentMask &mask,
                         const Tensor<1, dim> &value) {
      const types::boundary_id                  id = mesh.id(name, prm.case_file, entry);
      std::map<types::global_dof_index, double> values;
      VectorTools::interpolate_boundary_values(
          mapping, dof_u, id,
          Functions::ConstantFunction<dim>(std::vector<double>{value[0], value[1]}), values, mask);
      dirichlet.insert(values.begin(), values.end());
      velocity_boundaries.push_back({id, mask});
    };
    for (const auto &[list, entry, mask] :
         {std::make_tuple(&bc.no_slip, "Boundary conditions/No-slip", ComponentMask()),
          std::make_tuple(&bc.zero_x_velocity, "Boundary conditions/Zero x-velocity",
                          ComponentMask(std::vector<bool>{true, false})),
          std::make_tuple(&bc.zero_y_velocity, "Boundary conditions/Zero y-velocity",
                          ComponentMask(std::vector<bool>{false, true}))})
      for (const std::string &name : split_list(*list))
        add(name, entry, mask, Tensor<1, dim>());
    for (const auto &[name, value] : velocities)
      add(name, "Boundary conditions/Velocity", ComponentMask(), value);
    constrain_directions();
    const std::vector<CellList> pieces = mesh_pieces();
    require_no_free_rigid_motion(pieces); // also where there is no velocity condition at all
    require_no_net_inflow_into_a_closed_domain(pieces);

    // Every named boundary of the load must exist too (checked before anything is solved).
    for (const auto &[name, p] : parse_named_values(bc.external_pressure, prm.case_file,
                                                    "Boundary conditions/External pressure"))
      {
        external_pressures.emplace_back(
            mesh.id(name, prm.case_file, "Boundary conditions/External pressure"), p);
        const auto condition = condition_of.find(external_pressures.back().first);
        // A pressure does work only through the normal velocity (free on a Zero x-velocity
        // boundary y = const, for example).
        if (condition != condition_of.end() &&
            prescribed_normal_flux(condition->first, condition->second))
          throw InputError(prm.case_file, "Boundary conditions/External pressure",
                           "on '" + name + "', a " + condition->second +
                               " boundary, where the normal velocity is prescribed and a "
                               "pressure does nothing: expected a boundary where the normal "
                               "velocity is free");
      }
    const std::string stress_entry = "Boundary conditions/External stress";
    for (const auto &[name, sigma] :
         parse_named_stresses(bc.external_stress, prm.case_file, stress_entry))
      {
        const types::boundary_id id = mesh.id(name, prm.case_file, stress_entry);
        // The natural condition sigma_tot n = sigma_ext n (the sum of (20b) and (21)) holds on
        // B_N, where the velocity is free; where a velocity condition fixes some direction, the
        // reaction there would take up the stress's part along it.
        if (const auto condition = condition_of.find(id); condition != condition_of.end())
          throw InputError(prm.case_file, stress_entry,
                           "on '" + name + "', a " + condition->second +
                               " boundary: expected a boundary with no velocity condition (for "
                               "a normal load on a boundary with one velocity component fixed, "
                               "use External pressure)");
        for (const auto &[pressed, p_ext] : external_pressures)
          if (pressed == id)
            throw InputError(prm.case_file, stress_entry,
                             "on '" + name +
                                 "', which is also in Boundary conditions/External pressure: "
                                 "expected one load per boundary (a pressure p is the stress "
                                 "(-p, 0, -p))");
        external_stresses.emplace_back(id, sigma);
      }
    warn_of_tension();
    const std::string traction_entry = "Boundary conditions/Analytic traction";
    for (const std::string &name : split_list(bc.analytic_traction))
      {
        // the reference's whole stress there, a natural condition like External stress
        const types::boundary_id id = mesh.id(name, prm.case_file, traction_entry);
        if (const auto condition = condition_of.find(id); condition != condition_of.end())
          throw InputError(prm.case_file, traction_entry,
                           "on '" + name + "', a " + condition->second +
                               " boundary: expected a boundary with no velocity condition (the "
                               "traction is the analytic stress there)");
        analytic_tractions.push_back(id);
      }
    if (!prm.output.drag_boundary.empty())
      {
        // The force is the reaction where the velocity is constrained (boundary_force()).
        if (!condition_of.count(
                mesh.id(prm.output.drag_boundary, prm.case_file, "Output/Drag boundary")))
          throw InputError(prm.case_file, "Output/Drag boundary",
                           "'" + prm.output.drag_boundary +
                               "' has no velocity condition: expected a boundary in one of "
                               "the velocity conditions of Boundary conditions (the force is "
                               "its reaction)");
      }
    if (!prm.output.inflow_boundary.empty())
      {
        // U_infinity is the mean inflow speed there: 0 by the condition on a wall, which made a
        // flowing channel "jammed" (C_D null) with exit 0.
        const auto id =
            mesh.id(prm.output.inflow_boundary, prm.case_file, "Output/Inflow boundary");
        if (const auto condition = condition_of.find(id); condition != condition_of.end())
          if (const auto flux = prescribed_normal_flux(id, condition->second); flux && flux->zero)
            throw InputError(prm.case_file, "Output/Inflow boundary",
                             "'" + prm.output.inflow_boundary + "' is in Boundary conditions/" +
                                 condition->second +
                                 ", which holds its normal velocity at 0, so no material "
                                 "crosses it: expected the boundary the material enters by");
      }
  }

  /// A granular material carries no tension: lambda_N >= 0 (the cone K_mu of (16)). A load
  /// that pulls on a boundary (a negative External pressure, an External stress with n .
  /// sigma_ext n > 0 on some face) is resisted only by the viscous stress 2/Re D^b(u), so the
  /// material there dilates (div u > 0); more often it is a sign written the wrong way (tension
  /// is positive in sigma_ext), hence the warning.
  void
  Problem::warn_of_tension()
  {
    const QGauss<dim - 1> face_quadrature(1);
    FEFaceValues<dim>     fvf(mapping, fe_u, face_quadrature, update_normal_vectors);
    const auto            largest_pull = [&](const types::boundary_id id, const auto &sigma) {
      double pull = -std::numeric_limits<double>::infinity();
      for_each_face_on(dof_u, id, fvf, [&](const auto &) {
        const Tensor<1, dim> n = fvf.normal_vector(0);
        pull                   = std::max(pull, n * (sigma * n));
      });
      return pull;
    };
    const auto warn = [&](const std::string &entry, const types::boundary_id id, const double pull,
                          const std::string &convention) {
      std::string name;
      for (const auto &[n, i] : mesh.boundary_ids)
        if (i == id)
          name = n;
      std::ostringstream w;
      w << std::setprecision(3) << "Boundary conditions/" << entry << " pulls on '" << name
        << "' (a normal traction of up to " << pull << " outwards; " << convention
        << "): the "
           "granular stress carries no tension (lambda_N >= 0), only the viscous stress "
           "2/Re D^b(u) resists it, and the material there dilates";
      report.warn(w.str());
    };
    for (const auto &[id, p_ext] : external_pressures)
      if (p_ext < 0.)
        warn("External pressure", id, -p_ext, "a negative pressure");
    for (const auto &[id, sigma] : external_stresses)
      if (const double pull = largest_pull(id, sigma); pull > 1e-12 * sigma.norm())
        warn("External stress", id, pull,
             "sigma_ext has tension positive, a pressure p is (-p, 0, -p)");
  }

  void
  Problem::number_free_dofs()
  {
    free_index.assign(dof_u.n_dofs(), -1);
    free_coefficient.assign(dof_u.n_dofs(), 1.);
    reaction_dof.assign(dof_u.n_dofs(), false);
    std::map<types::global_dof_index, types::global_dof_index> partner;
    for (const auto &[x, node] : directed_nodes)
      {
        // u = w t with t = d rotated by +90 degrees, its larger component positive (so that
        // d = +-e_x gives t = e_y, the same unknown as Zero x-velocity).
        Tensor<1, dim> t({-node.second[1], node.second[0]});
        if (std::abs(t[0]) >= std::abs(t[1]) ? t[0] < 0. : t[1] < 0.)
          t *= -1.;
        free_coefficient[x]          = t[0];
        free_coefficient[node.first] = t[1];
        partner[x]                   = node.first;
        partner[node.first]          = x;
        reaction_dof[x] = reaction_dof[node.first] = true;
      }
    for (types::global_dof_index i = 0; i < dof_u.n_dofs(); ++i)
      if (dirichlet.count(i))
        reaction_dof[i] = true;
      else if (const auto p = partner.find(i); p != partner.end() && free_index[p->second] >= 0)
        free_index[i] = free_index[p->second];
      else
        free_index[i] = static_cast<int>(n_free++);
  }

  void
  Problem::note_unconditioned_and_unresolved_boundaries()
  {
    // What a user may not have meant: a named boundary in no condition is traction-free (the
    // material leaves through a forgotten floor), and a boundary of one mesh edge is not
    // resolved (a silo outlet narrower than the mesh size jams on the mesh, not on the
    // rheology).
    std::map<types::boundary_id, std::size_t> edges;
    for (const auto &face : mesh.triangulation.active_face_iterators())
      if (face->at_boundary())
        ++edges[face->boundary_id()];
    std::set<types::boundary_id> conditioned;
    for (const auto &vb : velocity_boundaries)
      conditioned.insert(vb.id);
    for (const auto &[id, p] : external_pressures)
      conditioned.insert(id);
    for (const auto &[id, sigma] : external_stresses)
      conditioned.insert(id);
    conditioned.insert(analytic_tractions.begin(), analytic_tractions.end());
    std::string free;
    for (const auto &[name, id] : mesh.boundary_ids)
      {
        if (!conditioned.count(id))
          {
            free += (free.empty() ? "'" : ", '") + name + "'";
            traction_free.push_back(name);
          }
        if (edges[id] <= 1)
          report.warn(
              "boundary '" + name + "' is " + std::to_string(edges[id]) +
              " mesh edge: the mesh does not resolve it; a flow through or along it (an outlet, "
              "a jam) is "
              "the mesh's, not the model's: refine Geometry/Mesh size");
      }
    if (!free.empty())
      log.print("dp: note: no condition on " + free +
                ": traction-free (the material may leave or enter there)\n");
  }

  /// Zero normal and Zero tangential velocity: at each node of these faces, u . d = 0 along
  /// one direction d: the faces' normal (free slip) or tangent (flow normal to the boundary).
  /// Where faces meet at an angle, d is sum_f w_f d_f normalised, w_f the integral of the
  /// node's shape function on face f (each d_f turned to agree in sign with the first): for a
  /// slip wall, Engelman's consistent normal, with which the flux through the wall is zero in
  /// all (each face's is not, at a kink). That lets the flow follow a polygonal wall, or the
  /// chords of a curved one, round its kinks. Where two faces' directions differ by more than 45
  /// degrees, as at the corner of a box, no direction is free and the node is fixed (u = 0); so
  /// is a node where another velocity condition already fixes a component other than along d.
  void
  Problem::constrain_directions()
  {
    const auto &bc  = prm.boundaries;
    using Direction = VelocityBoundary::Direction;
    std::map<types::boundary_id, Direction> direction_of;
    for (const auto &[list, direction, entry] :
         {std::make_tuple(&bc.zero_normal_velocity, Direction::normal,
                          "Boundary conditions/Zero normal velocity"),
          std::make_tuple(&bc.zero_tangential_velocity, Direction::tangent,
                          "Boundary conditions/Zero tangential velocity")})
      for (const std::string &name : split_list(*list))
        {
          const types::boundary_id id = mesh.id(name, prm.case_file, entry);
          direction_of[id]            = direction;
          velocity_boundaries.push_back({id, ComponentMask(dim, false), direction});
        }
    if (direction_of.empty())
      return;

    struct Node
    {
      types::global_dof_index     y;
      Tensor<1, dim>              sum;  // sum_f w_f d_f, signs aligned
      std::vector<Tensor<1, dim>> n;    // the outward normal of each face
      std::vector<Direction>      kind; // and its condition
    };
    std::map<types::global_dof_index, Node> nodes; // by x-dof
    for_each_boundary_node([&](const types::boundary_id b, const Tensor<1, dim> &n,
                               const types::global_dof_index x, const types::global_dof_index y,
                               const double w) {
      const auto direction = direction_of.find(b);
      if (direction == direction_of.end())
        return;
      const Tensor<1, dim> d    = VelocityBoundary::fixed_direction(direction->second, n);
      Node                &node = nodes[x];
      node.y                    = y;
      const bool agrees =
          node.n.empty() || VelocityBoundary::fixed_direction(node.kind[0], node.n[0]) * d >= 0.;
      node.sum += (agrees ? w : -w) * d;
      node.n.push_back(n);
      node.kind.push_back(direction->second);
    });

    const double cos_corner = std::cos(numbers::PI / 4.), cos_same = std::cos(numbers::PI / 180.);
    for (const auto &[x, node] : nodes)
      {
        const bool fixed_x = dirichlet.count(x), fixed_y = dirichlet.count(node.y);
        if (fixed_x && fixed_y)
          continue; // No-slip
        // Faces with the same condition may meet at a kink of up to 45 degrees (their outward
        // normals within 45 degrees, signs included: the two walls of a narrow V are a
        // corner). Faces with different conditions share a node only if they fix the same
        // direction (a slip floor and the end of a channel normal to it), to 1 degree.
        const auto d_of = [&](const std::size_t f) {
          return VelocityBoundary::fixed_direction(node.kind[f], node.n[f]);
        };
        bool corner = false;
        for (std::size_t a = 0; a < node.n.size(); ++a)
          for (std::size_t b = 0; b < a; ++b)
            corner =
                corner || (node.kind[a] == node.kind[b] ? node.n[a] * node.n[b] < cos_corner
                                                        : std::abs(d_of(a) * d_of(b)) < cos_same);
        Tensor<1, dim> d = node.sum / node.sum.norm();
        for (unsigned int c = 0; c < dim; ++c) // an axis stays an axis, to the last bit
          if (std::abs(d[c]) < 1e-14)
            d[c] = 0.;
        d /= d.norm();
        // A component already fixed (Zero x- or y-velocity) leaves nothing free unless d is
        // that component's axis, when u . d = 0 holds already.
        if (fixed_x || fixed_y)
          corner = corner || std::abs(d[fixed_x ? 1 : 0]) > 1e-12;
        if (corner)
          {
            dirichlet.emplace(x, 0.);
            dirichlet.emplace(node.y, 0.);
          }
        else if (!fixed_x && !fixed_y)
          directed_nodes[x] = {node.y, d};
      }
  }

  /// The mesh's edge-connected pieces (a user mesh may have several), each as its cells.
  std::vector<Problem::CellList>
  Problem::mesh_pieces() const
  {
    std::vector<CellList> pieces;
    std::vector<bool>     seen_cell(mesh.triangulation.n_active_cells(), false);
    for (const auto &seed : dof_u.active_cell_iterators())
      {
        if (seen_cell[seed->active_cell_index()])
          continue;
        CellList stack{seed}, cells;
        seen_cell[seed->active_cell_index()] = true;
        while (!stack.empty())
          {
            const auto cell = stack.back();
            stack.pop_back();
            cells.push_back(cell);
            for (const unsigned int f : cell->face_indices())
              if (!cell->at_boundary(f) && !seen_cell[cell->neighbor(f)->active_cell_index()])
                {
                  seen_cell[cell->neighbor(f)->active_cell_index()] = true;
                  stack.push_back(cell->neighbor(f));
                }
          }
        pieces.push_back(std::move(cells));
      }
    return pieces;
  }

  Point<dim>
  Problem::centre_of(const CellList &piece)
  {
    Point<dim> centre;
    for (const auto &cell : piece)
      centre += cell->center() / static_cast<double>(piece.size());
    return centre;
  }

  std::string
  Problem::where_in_mesh(const CellList &piece) const
  {
    if (piece.size() == mesh.triangulation.n_active_cells())
      return "";
    const Point<dim>   centre = centre_of(piece);
    std::ostringstream where;
    where << "the part of the mesh around (" << centre[0] << ", " << centre[1] << ") ("
          << piece.size() << " of " << mesh.triangulation.n_active_cells()
          << " triangles, joined to the rest by no edge)";
    return where.str();
  }

  /// A (25a) vanishes on rigid motions (D(u) = 0), so the velocity conditions must leave none
  /// free on any piece of the mesh; else A is singular, and a Cholesky factorisation in floating
  /// point need not notice (tiny positive pivots): the velocity would come out as 1e14 with a
  /// "converged" residual. On each edge-connected piece, the rigid motions u = (a - w y, b + w x)
  /// that vanish at the constrained dofs are the kernel of the rows (1, 0, -y) for an x-dof and
  /// (0, 1, x) for a y-dof (coordinates centred and scaled on the piece): their Gram matrix must
  /// be regular.
  void
  Problem::require_no_free_rigid_motion(const std::vector<CellList> &pieces) const
  {
    std::map<types::global_dof_index, Point<dim>> support;
    DoFTools::map_dofs_to_support_points(mapping, dof_u, support);
    std::vector<types::global_dof_index> dofs(fe_u.n_dofs_per_cell());
    for (const CellList &cells : pieces)
      {
        const Point<dim> centre = centre_of(cells);
        double           size   = 0.;
        for (const auto &cell : cells)
          for (const unsigned int v : cell->vertex_indices())
            size = std::max(size, cell->vertex(v).distance(centre));
        SymmetricTensor<2, 3>             gram;
        std::set<types::global_dof_index> seen;
        for (const auto &cell : cells)
          {
            cell->get_dof_indices(dofs);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              {
                const auto directed = directed_nodes.find(dofs[i]);
                if ((!dirichlet.count(dofs[i]) && directed == directed_nodes.end()) ||
                    !seen.insert(dofs[i]).second)
                  continue;
                // The velocity along e (a component, or the constrained direction d) is zero.
                Tensor<1, dim> e;
                if (directed != directed_nodes.end())
                  e = directed->second.second;
                else
                  e[fe_u.system_to_component_index(i).first] = 1.;
                const Tensor<1, dim> x = (support.at(dofs[i]) - centre) / size;
                const Tensor<1, 3>   row({e[0], e[1], e[1] * x[0] - e[0] * x[1]});
                gram += symmetrize(outer_product(row, row));
              }
          }
        const auto modes = eigenvectors(gram); // descending: modes.back() is the least fixed
        if (modes.back().first > 1e-10 * std::max(trace(gram), 1.))
          continue;
        Tensor<1, 3> m = modes.back().second;
        if (std::abs(m[0]) >= std::abs(m[1]) ? m[0] < 0. : m[1] < 0.)
          m *= -1.;
        std::ostringstream what;
        if (trace(gram) == 0.)
          what << "no velocity condition applies";
        else if (std::abs(m[2]) > std::hypot(m[0], m[1]))
          what << "the velocity can still rotate";
        else
          {
            // rounding's 1e-17 printed as 0
            const auto component = [&](const double c) {
              const double x = c / std::hypot(m[0], m[1]);
              return std::abs(x) < 1e-9 ? 0. : x;
            };
            what << std::setprecision(3) << "the velocity can still translate along ("
                 << component(m[0]) << ", " << component(m[1]) << ")";
          }
        const std::string where = where_in_mesh(cells);
        // Named as the whole subsection: any of its velocity conditions can fix the motion.
        throw InputError(prm.case_file, "Boundary conditions",
                         "with its velocity conditions (" +
                             velocity_condition_entries(prm.boundaries) + ") " + what.str() +
                             (where.empty() ? "" : " on " + where) +
                             " (A is singular): expected velocity conditions that fix both "
                             "translations and the rotation of every part of the mesh");
      }
  }

  /// In a domain whose every boundary face has its normal velocity prescribed, int div u =
  /// int u_D . n: where Boundary conditions/Velocity pushes more material in than it lets out,
  /// no velocity has div u >= 0 (24) and the cone problem has no solution; the solvers would
  /// only say that they did not converge. The flux is that of the interpolated u_D, the one
  /// the discrete problem sees. Each piece of the mesh is a domain of its own.
  void
  Problem::require_no_net_inflow_into_a_closed_domain(const std::vector<CellList> &pieces) const
  {
    if (prm.boundaries.velocity.empty())
      return;
    const QGauss<dim - 1>            face_quadrature(3); // u_D is P2 on straight faces
    FEFaceValues<dim>                fvf(mapping, fe_u, face_quadrature,
                                         update_values | update_normal_vectors | update_JxW_values);
    const FEValuesExtractors::Vector velocity(0);
    Vector<double>                   u_D(dof_u.n_dofs());
    for (const auto &[i, value] : dirichlet)
      u_D[i] = value;
    std::vector<Tensor<1, dim>> values(face_quadrature.size());
    // The net and the gross flux into a piece, or nothing if a face of it is open.
    const auto closed_flux =
        [&](const CellList &piece) -> std::optional<std::pair<double, double>> {
      double net = 0., gross = 0.;
      for (const auto &cell : piece)
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              fvf.reinit(cell, f);
              const Tensor<1, dim> n = fvf.normal_vector(0);
              // closed: both components fixed (No-slip, Velocity), the normal one (free slip),
              // or the one component fixed (Zero x- or y-velocity) is the normal's
              bool closed = false;
              for (const auto &vb : velocity_boundaries)
                if (vb.id == cell->face(f)->boundary_id())
                  {
                    if (vb.direction == VelocityBoundary::Direction::normal ||
                        (vb.direction == VelocityBoundary::Direction::none &&
                         vb.mask.n_selected_components(dim) == dim))
                      closed = true;
                    else if (vb.direction == VelocityBoundary::Direction::none)
                      for (unsigned int c = 0; c < dim; ++c)
                        closed = closed || (vb.mask[c] && std::abs(n[c]) > 1. - 1e-12);
                  }
              if (!closed)
                return std::nullopt; // material can leave (or enter) through this face
              fvf[velocity].get_function_values(u_D, values);
              double flux = 0.;
              for (unsigned int q = 0; q < face_quadrature.size(); ++q)
                flux += values[q] * fvf.normal_vector(q) * fvf.JxW(q);
              net += flux;
              gross += std::abs(flux);
            }
      return std::make_pair(net, gross);
    };
    for (const CellList &piece : pieces)
      if (const auto flux = closed_flux(piece); flux && flux->first < -1e-9 * flux->second)
        {
          const std::string  where = where_in_mesh(piece);
          std::ostringstream what;
          what << std::setprecision(3) << "pushes a net volume flux of " << -flux->first << " into "
               << (where.empty() ? "a domain" : where)
               << " that the velocity conditions close on every side; the material "
                  "cannot be compressed (div u >= 0, Daviet (24)): expected velocities whose "
                  "outflow is at least their inflow, or a boundary left open (one with no "
                  "velocity "
                  "condition, External pressure or External stress)";
          throw InputError(prm.case_file, "Boundary conditions/Velocity", what.str());
        }
  }
} // namespace granflow::dp::detail
