// Postprocessing on deal.II fields: values and gradients along a line (the profiles the papers
// plot) and boundary integrals (drag, mean inflow velocity).
#pragma once

#include <deal.II/base/point.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace granflow::postprocess
{
  struct LineSamples
  {
    std::vector<dealii::Point<2>>                          points;
    std::vector<dealii::Vector<double>>                    values;    // per point, per component
    std::vector<std::vector<dealii::Tensor<1, 2>>>         gradients; // per point, per component
  };

  /// Samples a finite-element field at n equidistant points from a to b (end points nudged inside
  /// by 1e-9 of the length so they are found on the closed domain). Points outside the mesh (a
  /// line across a hole, or past the boundary) are left out.
  LineSamples
  sample_line(const dealii::Mapping<2>       &mapping,
              const dealii::DoFHandler<2>    &dof_handler,
              const dealii::Vector<double>   &field,
              const dealii::Point<2>         &a,
              const dealii::Point<2>         &b,
              unsigned int                    n);

  /// int_Gamma f(x) n dS of a scalar FE field f over the faces with boundary id `id`
  /// (n the outward normal of the domain).
  dealii::Tensor<1, 2>
  boundary_flux(const dealii::Mapping<2>     &mapping,
                const dealii::DoFHandler<2>  &dof_handler,
                const dealii::Vector<double> &field,
                dealii::types::boundary_id    id);

  /// Of a 2-component vector FE field u over boundary `id`: int_Gamma u . n dS (n outward),
  /// |Gamma|, and the mean of u_x over Gamma (which way a channel flow runs through it).
  struct BoundaryFlux
  {
    double flux = 0., length = 0., mean_u_x = 0.;
  };
  BoundaryFlux
  boundary_normal_flux(const dealii::Mapping<2> &mapping, const dealii::DoFHandler<2> &dof_handler,
                       const dealii::Vector<double> &velocity, dealii::types::boundary_id id);
} // namespace granflow::postprocess
