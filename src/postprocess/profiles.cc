#include "postprocess/profiles.h"

#include <deal.II/base/quadrature.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/grid_tools_cache.h>

#include <stdexcept>

namespace granflow::postprocess
{
  using namespace dealii;

  LineSamples
  sample_line(const Mapping<2>     &mapping,
              const DoFHandler<2>  &dof_handler,
              const Vector<double> &field,
              const Point<2>       &a,
              const Point<2>       &b,
              const unsigned int    n)
  {
    const auto        &fe = dof_handler.get_fe();
    GridTools::Cache<2> cache(dof_handler.get_triangulation(), mapping);
    LineSamples         samples;
    const double        nudge = 1e-9;
    for (unsigned int k = 0; k < n; ++k)
      {
        double t = n > 1 ? double(k) / (n - 1) : 0.;
        t        = nudge + (1. - 2. * nudge) * t;
        const Point<2> p = a + t * (b - a);
        const auto found = GridTools::find_active_cell_around_point(cache, p);
        if (found.first == dof_handler.get_triangulation().end())
          continue; // outside the domain (a hole, or past its boundary): no sample
        const typename DoFHandler<2>::active_cell_iterator cell(&dof_handler.get_triangulation(),
                                                                found.first->level(),
                                                                found.first->index(),
                                                                &dof_handler);
        FEValues<2> fv(mapping, fe, Quadrature<2>(found.second), update_values | update_gradients);
        fv.reinit(cell);
        std::vector<Vector<double>>              v(1, Vector<double>(fe.n_components()));
        std::vector<std::vector<Tensor<1, 2>>>   g(1, std::vector<Tensor<1, 2>>(fe.n_components()));
        fv.get_function_values(field, v);
        fv.get_function_gradients(field, g);
        samples.points.push_back(p);
        samples.values.push_back(v[0]);
        samples.gradients.push_back(g[0]);
      }
    return samples;
  }

  Tensor<1, 2>
  boundary_flux(const Mapping<2>          &mapping,
                const DoFHandler<2>       &dof_handler,
                const Vector<double>      &field,
                const types::boundary_id   id)
  {
    QGauss<1>    quadrature(3);
    FEFaceValues<2> fv(mapping, dof_handler.get_fe(), quadrature,
                       update_values | update_normal_vectors | update_JxW_values);
    std::vector<double> f(quadrature.size());
    Tensor<1, 2>        result;
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (const unsigned int face : cell->face_indices())
        if (cell->face(face)->at_boundary() && cell->face(face)->boundary_id() == id)
          {
            fv.reinit(cell, face);
            fv.get_function_values(field, f);
            for (unsigned int q = 0; q < quadrature.size(); ++q)
              result += f[q] * fv.normal_vector(q) * fv.JxW(q);
          }
    return result;
  }

  BoundaryFlux
  boundary_normal_flux(const Mapping<2> &mapping, const DoFHandler<2> &dof_handler,
                       const Vector<double> &velocity, const types::boundary_id id)
  {
    QGauss<1>       quadrature(3);
    FEFaceValues<2> fv(mapping, dof_handler.get_fe(), quadrature,
                       update_values | update_normal_vectors | update_JxW_values);
    std::vector<Vector<double>> u(quadrature.size(), Vector<double>(2));
    BoundaryFlux                result;
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (const unsigned int face : cell->face_indices())
        if (cell->face(face)->at_boundary() && cell->face(face)->boundary_id() == id)
          {
            fv.reinit(cell, face);
            fv.get_function_values(velocity, u);
            for (unsigned int q = 0; q < quadrature.size(); ++q)
              {
                result.flux +=
                    (u[q][0] * fv.normal_vector(q)[0] + u[q][1] * fv.normal_vector(q)[1]) *
                    fv.JxW(q);
                result.length += fv.JxW(q);
                result.mean_u_x += u[q][0] * fv.JxW(q);
              }
          }
    if (result.length > 0.)
      result.mean_u_x /= result.length;
    return result;
  }
} // namespace granflow::postprocess
