// A mapping whose results do not depend on the number of threads: a case gives the same bits
// with any DEAL_II_NUM_THREADS (on one machine and build; another CPU, compiler or BLAS may round
// differently).
//
// deal.II 9.4's FEValues reuses the Jacobian and the shape gradients of the previous cell when the
// new cell is a translation of it, but only when deal.II runs one thread
// (FEValuesBase::check_cell_similarity); with more threads every cell is computed afresh. The two
// agree to rounding, not bit for bit: on the default cylinder two cells' matrices differed by
// 2e-16 between DEAL_II_NUM_THREADS=1 and 2, and the interior point near its floor turned that
// into a run that converged with one thread and stalled with two (found in session 10: the mu = 0.5
// cylinder at p_ext = 0.2, 9.5e-7 against 1.86e-6). The shear column's mu_wall differed by 1e-12.
//
// Mapping::fill_fe_values receives the similarity FEValues detected and returns the one that the
// finite element is then evaluated with; CellSimilarity::invalid_next_cell (what MappingQEulerian
// returns, whose cells move) makes both compute every cell afresh, whatever the thread count.
#pragma once

#include <deal.II/fe/mapping.h>

#include <memory>

namespace granflow
{
  /// Base<dim, spacedim> (MappingFE, MappingQ), evaluating every cell afresh.
  template <template <int, int> class Base, int dim, int spacedim = dim>
  class WithoutCellSimilarity : public Base<dim, spacedim>
  {
  public:
    using Base<dim, spacedim>::Base;

    std::unique_ptr<dealii::Mapping<dim, spacedim>>
    clone() const override
    {
      return std::make_unique<WithoutCellSimilarity>(*this);
    }

    dealii::CellSimilarity::Similarity
    fill_fe_values(const typename dealii::Triangulation<dim, spacedim>::cell_iterator &cell,
                   const dealii::CellSimilarity::Similarity,
                   const dealii::Quadrature<dim>                                   &quadrature,
                   const typename dealii::Mapping<dim, spacedim>::InternalDataBase &data,
                   dealii::internal::FEValuesImplementation::MappingRelatedData<dim, spacedim>
                       &output) const override
    {
      Base<dim, spacedim>::fill_fe_values(cell, dealii::CellSimilarity::none, quadrature, data,
                                          output);
      return dealii::CellSimilarity::invalid_next_cell;
    }
  };
} // namespace granflow
