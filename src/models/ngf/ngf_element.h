// The two-field (u, g) elements of Henann & Kamrin 2016, Section 3: residuals (35) and their
// consistent Jacobian (66)-(89), with the F-bar method of de Souza Neto et al. (1996) against
// volumetric locking. The same linear shape functions interpolate u and g (32)-(33). Two
// kinematics share one point-level assembly:
// - brick: the 8-node hexahedron, nodal (u_x, u_y, u_z, g);
// - axisymmetric: the 4-node generalized-axisymmetric quad in (R, Z) with nodal (u_r, u_z, theta,
// g),
//   theta the angle of rotation about the axis, so that circumferential shear is represented. With
//   r = R + u_r, the motion is x = r e_r(Theta + theta) + (Z + u_z) e_z, and in the frames
//   (e_r, e_phi, e_z) x (E_R, E_Theta, E_Z)
//       F = [[1 + u_r,R, 0, u_r,Z], [r theta,R, r / R, r theta,Z], [u_z,R, 0, 1 + u_z,Z]].
//   Integrals are per radian (dV = R dR dZ); the theta equation is the balance of moments.
//
// The virtual work of dof i is int T : (G_i F^{-1}) dv with G_i = Grad(dx_i) the gradient of its
// virtual displacement; for the brick G_i = dF/dU_i, for the quad the virtual rotation N r e_phi
// also turns the local frame, so G_i differs from dF/dU_i and depends on the current state. The
// Jacobian of dof pair (i, j) is then
//     int [ H_i : C : dL_j + H_i : Q (tr dL0_j - tr dL_j) + T : (dG_i/dU_j F^{-1}) ] dv,
// H_i = G_i F^{-1}, dL_j = (dF/dU_j) F^{-1}, C the spatial tangent (68), Q = C_ijmm / 3 - 2 T / 3
// the F-bar term, dL0 the same at the centroid.
//
// Element dofs are node-major: index 4 a + c, c = 0, 1, 2 the displacement-type unknowns, c = 3 the
// fluidity. Signs: the element returns r = [f_int - f_body ; R_g] and J = dr/dU, so a Newton step
// solves J dU = -r. In the paper's notation J = [K_uu, K_ug ; -K_gu, -K_gg] (37). External surface
// terms (traction, fluidity flux) are added by the model.
#pragma once

#include "rheology/finite_strain.h"

#include <deal.II/base/tensor.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace granflow::ngf
{
  enum class Kinematics
  {
    brick,       ///< 3D, reference coordinates (X, Y, Z)
    axisymmetric ///< generalized axisymmetric with twist, reference coordinates (R, Z)
  };

  /// Shape functions of one element in the reference configuration. Gradients have three
  /// components in the reference frame: (d/dX, d/dY, d/dZ) for the brick, (d/dR, 0, d/dZ) for the
  /// quad.
  struct ElementShape
  {
    std::vector<double>              JxW; ///< [q] reference weights (area for the quad)
    std::vector<double>              R;   ///< [q] radius (quad only)
    std::vector<std::vector<double>> N;   ///< [q][a]
    std::vector<std::vector<dealii::Tensor<1, 3>>> dN_dX;          ///< [q][a]
    std::vector<double>                            N_centroid;     ///< [a], for F-bar
    std::vector<dealii::Tensor<1, 3>>              dN_dX_centroid; ///< [a]
    double                                         R_centroid = 0.;
  };

  struct ElementInput
  {
    std::vector<dealii::Tensor<1, 3>> u;    ///< [a] (u_x, u_y, u_z) or (u_r, u_z, theta) at t_{n+1}
    std::vector<double>               g;    ///< [a] nodal fluidities at t_{n+1}
    std::vector<rheology::Tensor2>    Fp_n; ///< [q] plastic distortion at t_n
    double                            dt = 0.;
    dealii::Tensor<1, 3> body_force; ///< b_0 per unit reference volume (27), local frame
  };

  struct ElementOutput
  {
    dealii::Vector<double> residual;
    /// per dof, the sum of the magnitudes of the residual's terms (T : H_i dv; grad g . grad N dv,
    /// N g / xi^2 dv, N g_loc / xi^2 dv): the scale against which the residual is small
    dealii::Vector<double>                     magnitude;
    dealii::FullMatrix<double>                 jacobian;
    std::vector<rheology::NonlocalPointUpdate> points; ///< [q] the constitutive state
  };

  class NonlocalElement
  {
  public:
    /// `local`: the local variant g = g_loc (Henann 6.3, Fig. 7); the element's fluidity unknowns
    /// are then unused (the model constrains them).
    NonlocalElement(Kinematics kinematics, const rheology::ElasticModuli &moduli,
                    const rheology::NonlocalParameters &material, bool local = false)
        : kinematics(kinematics)
        , moduli(moduli)
        , material(material)
        , local(local)
    {
    }

    /// Residual and (if wanted) Jacobian of one element. A non-finite or inverted iterate gives a
    /// non-finite residual, so that the driver cuts the increment.
    void
    evaluate(const ElementShape &shape, const ElementInput &in, bool with_jacobian,
             ElementOutput &out) const;

  private:
    Kinematics                   kinematics;
    rheology::ElasticModuli      moduli;
    rheology::NonlocalParameters material;
    bool                         local;
  };
} // namespace granflow::ngf
