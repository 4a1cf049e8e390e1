// The two-field (u, g) 8-node brick of Henann & Kamrin 2016, Section 3: residuals (35) and their
// consistent Jacobian (66)-(89), with the F-bar method of de Souza Neto et al. (1996) against
// volumetric locking. The same trilinear shape functions interpolate u and g (32)-(33).
//
// Element dofs are node-major: index 4 a + c, c = 0, 1, 2 the displacement components, c = 3 the
// fluidity. Signs: the element returns r = [f_int - f_body ; R_g] and J = dr/d(u, g), so a Newton
// step solves J dU = -r. In the paper's notation J = [K_uu, K_ug ; -K_gu, -K_gg] (37).
// External surface terms (traction, fluidity flux) are added by the model.
#pragma once

#include "rheology/finite_strain.h"

#include <deal.II/base/tensor.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace granflow::ngf
{
  /// Shape functions of one element in the reference configuration.
  struct ElementShape
  {
    std::vector<double>                            JxW;   ///< [q] reference volume weights
    std::vector<std::vector<double>>               N;     ///< [q][a]
    std::vector<std::vector<dealii::Tensor<1, 3>>> dN_dX; ///< [q][a]
    std::vector<dealii::Tensor<1, 3>>              dN_dX_centroid; ///< [a], for F-bar
  };

  struct ElementInput
  {
    std::vector<dealii::Tensor<1, 3>> u;     ///< [a] nodal displacements at t_{n+1}
    std::vector<double>               g;     ///< [a] nodal fluidities at t_{n+1}
    std::vector<rheology::Tensor2>    Fp_n;  ///< [q] plastic distortion at t_n
    double                            dt = 0.;
    dealii::Tensor<1, 3>              body_force; ///< b_0 per unit reference volume (27)
  };

  struct ElementOutput
  {
    dealii::Vector<double>                     residual;
    dealii::FullMatrix<double>                 jacobian;
    std::vector<rheology::NonlocalPointUpdate> points; ///< [q] the constitutive state
    double                                     J_centroid = 1.;
  };

  class NonlocalBrick
  {
  public:
    NonlocalBrick(const rheology::ElasticModuli &moduli, const rheology::NonlocalParameters &material)
      : moduli(moduli)
      , material(material)
    {}

    /// Residual and (if wanted) Jacobian of one element.
    void
    evaluate(const ElementShape &shape, const ElementInput &in, bool with_jacobian, ElementOutput &out) const;

  private:
    rheology::ElasticModuli      moduli;
    rheology::NonlocalParameters material;
  };
} // namespace granflow::ngf
