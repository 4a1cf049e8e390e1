// Finite-deformation elasto-viscoplasticity of the nonlocal granular rheology:
// F = F^e F^p, Hencky elastic strain, Mandel/Kirchhoff stress from the quadratic Gibbs energy,
// the implicit time integration (exponential map, closed-form update (56)) and the algorithmically
// consistent tangents.
// Henann & Kamrin 2016: (9)-(20) model, Section 4 Steps 1-6 (60)-(65), Section 5 (66)-(89).
// Pure constitutive code on 3x3 tensors: no mesh, no FE.
//
// The update is done in the spatial frame: with B^e_tr = F^e_tr F^e_tr^T, the spatial trial Hencky
// strain is Ebar_tr = ln(B^e_tr) / 2 = R_tr E_tr R_tr^T (15), the Kirchhoff stress T^K = R M^e R^T
// (16), so (57) rotated by R_tr is (70) and no polar decomposition is formed explicitly.
#pragma once

#include "rheology/nonlocal_fluidity.h"

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

namespace granflow::rheology
{
  using Tensor2    = dealii::Tensor<2, 3>;
  using SymTensor2 = dealii::SymmetricTensor<2, 3>;
  using SymTensor4 = dealii::SymmetricTensor<4, 3>;
  using Tensor4    = dealii::Tensor<4, 3>;

  /// f(A) of a symmetric tensor and its derivative df/dA, f(A) = sum_a f(lambda_a) n_a (x) n_a.
  struct SymmetricFunction
  {
    SymTensor2 value;
    SymTensor4 derivative; ///< d f(A) / dA (minor-symmetric)
  };

  /// ln(A) of a symmetric positive definite A and d ln(A)/dA: the operator L of Henann (69).
  SymmetricFunction
  log_sym(const SymTensor2 &A);

  /// exp(A) of a symmetric A (the exponential map (38), (64)_3).
  SymTensor2
  exp_sym(const SymTensor2 &A);

  /// Shear modulus S and bulk modulus B of the Gibbs energy (12): M^e = C[E^e] (14).
  struct ElasticModuli
  {
    double S = 1e6; ///< [Pa], > 0
    double B = 1e7; ///< [Pa], > 0
  };

  /// State at t_{n+1} of one material point, and the consistent tangents of Section 5.
  struct NonlocalPointUpdate
  {
    Tensor2    Fp;               ///< F^p_{n+1} (64)_3
    SymTensor2 T;                ///< Cauchy stress (63)_4
    double     J           = 1.; ///< det F_{n+1}
    double     p           = 0.; ///< pbar_tr = pbar_{n+1} (52)_2, from the Mandel stress
    double     tau         = 0.; ///< taubar_{n+1} (63)_1
    double     mu          = 0.; ///< mu_{n+1} = taubar / pbar (63)_2
    double     gamma_dot_p = 0.; ///< (64)_1
    double     g_loc       = 0.; ///< (65)_1
    double     xi          = 0.; ///< (65)_2 with the cap
    double     g_res       = 0.; ///< (85)_2: (g - g_loc) / xi^2

    /// (67)-(68): C_ijkl = (1/J) F_lq dT^K_ij/dF_kq - T_il delta_jk. For a spatial perturbation
    /// dF = dL F: C_ijkl dL_kl = (1/J) dT^K_ij - T_il dL_jl (the dT_ij of (66) in the current
    /// frame).
    Tensor4    C;
    SymTensor2 Lambda;        ///< (81)-(82): dT/dg at fixed F
    Tensor2    dgres_dL;      ///< F_lq d g_res / dF_kq ((85)_1 without the g_res delta_kl of dv)
    double     dgres_dg = 0.; ///< d g_res / d g at fixed F (89), with the explicit 1/xi^2 term
  };

  /// F_{n+1} held as its displacement gradient H = F - 1 (with F-bar applied, if any). The elastic
  /// strain is small (p / B and tau / S are 1e-5 to 1e-4 at the paper's moduli), so F^e and
  /// B^e = F^e F^e^T differ from 1 by little. Formed from F itself, their O(1) entries carry an
  /// absolute round-off of 1e-16, a relative error of 1e-16 / epsilon^e in the stress; that error,
  /// varying with the iterate, is the floor of Newton's residual (docs/ngf.md). From H, the update
  /// forms F^e - 1 = H + P + H P and B^e - 1 directly and takes ln(B^e) through log1p of the
  /// eigenvalues of B^e - 1. What remains is the cancellation of H against P = F^p_n^{-1} - 1, a
  /// relative error of about 1e-16 |H| / epsilon^e: small while the total deformation is small, as
  /// in the yielding transient, and back to the old size once |H| is of order 1.
  struct DisplacementGradient
  {
    Tensor2 H; ///< F - 1

    Tensor2
    F() const
    {
      return dealii::unit_symmetric_tensor<3>() + H;
    }
  };

  /// det(1 + H) - 1 from the invariants of H, without cancellation for small H.
  double
  determinant_minus_one(const Tensor2 &H);

  /// Henann Section 4, Steps 1-6: given F_{n+1}, g_{n+1} and F^p_n, the state at t_{n+1} = t_n +
  /// dt. Guards the paper does not need to state (its solutions have pbar > 0 and g >= 0):
  /// - pbar_tr <= 0 (tension): (56) and (22) use pbar = 0, i.e. no shear strength and g_loc = 0;
  /// - g < 0 (a Newton iterate, or a discrete undershoot): the flow rule (18) uses max(g, 0), so
  /// the
  ///   plastic flow never reverses the stress, while g_res (85) keeps the actual g; at g = 0 the
  ///   tangents are the right derivatives.
  NonlocalPointUpdate
  nonlocal_update(const DisplacementGradient &F, const Tensor2 &Fp_n, double g, double dt,
                  const ElasticModuli &moduli, const NonlocalParameters &material,
                  bool with_tangents = true);
  /// The same from F itself (H = F - 1 is then only as precise as F's O(1) entries).
  NonlocalPointUpdate
  nonlocal_update(const Tensor2 &F, const Tensor2 &Fp_n, double g, double dt,
                  const ElasticModuli &moduli, const NonlocalParameters &material,
                  bool with_tangents = true);
  /// The local variant (Henann 6.3, Fig. 7): g = g_loc, no fluidity unknown. The update (55)_1 with
  /// the local flow rule (1) is linear in taubar and solved in closed form; C (68) is its
  /// consistent tangent. g_loc holds the resulting fluidity gamma_dot^p / mu; g_res, Lambda and
  /// dgres_* are zero.
  NonlocalPointUpdate
  local_update(const DisplacementGradient &F, const Tensor2 &Fp_n, double dt,
               const ElasticModuli &moduli, const NonlocalParameters &material,
               bool with_tangents = true);
  NonlocalPointUpdate
  local_update(const Tensor2 &F, const Tensor2 &Fp_n, double dt, const ElasticModuli &moduli,
               const NonlocalParameters &material, bool with_tangents = true);
} // namespace granflow::rheology
