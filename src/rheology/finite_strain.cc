#include "rheology/finite_strain.h"

#include <array>
#include <cmath>
#include <limits>

namespace granflow::rheology
{
  namespace
  {
    using dealii::SymmetricTensorEigenvectorMethod;

    using Eigen = std::array<std::pair<double, dealii::Tensor<1, 3>>, 3>;

    Eigen
    eigen(const SymTensor2 &A)
    {
      // deal.II's Jacobi iteration reports non-convergence on an already diagonal tensor (e.g. the
      // zero plastic increment of an elastic step), so diagonal tensors take the trivial path.
      if (A[0][1] == 0. && A[0][2] == 0. && A[1][2] == 0.)
        {
          Eigen e;
          for (unsigned int a = 0; a < 3; ++a)
            {
              e[a].first            = A[a][a];
              e[a].second           = dealii::Tensor<1, 3>();
              e[a].second[a]        = 1.;
            }
          return e;
        }
      // A non-finite tensor (from a diverging Newton iterate) gives non-finite eigenpairs, so that the
      // caller sees a non-finite residual and cuts the step instead of stopping in deal.II.
      Eigen nan;
      for (auto &e : nan)
        e.first = std::numeric_limits<double>::quiet_NaN();
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = i; j < 3; ++j)
          if (!std::isfinite(A[i][j]))
            return nan;
      try
        {
          return dealii::eigenvectors(A, SymmetricTensorEigenvectorMethod::jacobi);
        }
      catch (const dealii::ExceptionBase &)
        {
          return nan; // no convergence of the Jacobi sweeps
        }
    }

    SymTensor2
    spectral_sum(const Eigen &e, const std::array<double, 3> &f)
    {
      SymTensor2 r;
      for (unsigned int a = 0; a < 3; ++a)
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = i; j < 3; ++j)
            r[i][j] += f[a] * e[a].second[i] * e[a].second[j];
      return r;
    }

    /// (ln a - ln b) / (a - b), and 1/a for a == b, without cancellation for close a, b.
    double
    log_divided_difference(const double a, const double b)
    {
      const double x = (a - b) / b;
      if (std::abs(x) < 1e-4)
        return (1. - x / 2. + x * x / 3.) / b;
      return std::log1p(x) / (a - b);
    }

    SymTensor2
    deviator(const SymTensor2 &A)
    {
      return dealii::deviator(A);
    }
  } // namespace

  namespace
  {
    /// ln of a symmetric positive definite tensor from its eigenpairs, and d ln(A)/dA if asked.
    SymmetricFunction
    log_from_eigen(const Eigen &e, const bool with_derivative)
    {
    std::array<double, 3>  f;
    for (unsigned int a = 0; a < 3; ++a)
      f[a] = std::log(e[a].first);

    SymmetricFunction r;
    r.value = spectral_sum(e, f);
    if (!with_derivative)
      return r;
    // d f(A) : dA = sum_ab theta_ab (n_a . dA n_b) n_a (x) n_b, theta_aa = f'(lambda_a),
    // theta_ab = (f(lambda_a) - f(lambda_b)) / (lambda_a - lambda_b): the classical derivative of an
    // isotropic tensor function (de Souza Neto et al. 2008, Appendix A), smooth at equal eigenvalues.
    for (unsigned int a = 0; a < 3; ++a)
      for (unsigned int b = 0; b < 3; ++b)
        {
          const double theta = log_divided_difference(e[a].first, e[b].first);
          const auto  &na    = e[a].second;
          const auto  &nb    = e[b].second;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = i; j < 3; ++j)
              for (unsigned int k = 0; k < 3; ++k)
                for (unsigned int l = k; l < 3; ++l)
                  {
                    // symmetrised in (i, j) and (k, l); the sum over (a, b) symmetrises the rest
                    const double v = 0.5 * (na[i] * nb[j] + nb[i] * na[j]) * 0.5 *
                                     (na[k] * nb[l] + nb[k] * na[l]);
                    r.derivative[i][j][k][l] += theta * v;
                  }
        }
    return r;
  }
  } // namespace

  SymmetricFunction
  log_sym(const SymTensor2 &A)
  {
    return log_from_eigen(eigen(A), true);
  }

  SymTensor2
  exp_sym(const SymTensor2 &A)
  {
    const Eigen           e = eigen(A);
    std::array<double, 3> f;
    for (unsigned int a = 0; a < 3; ++a)
      f[a] = std::exp(e[a].first);
    return spectral_sum(e, f);
  }

  NonlocalPointUpdate
  nonlocal_update(const Tensor2            &F,
                  const Tensor2            &Fp_n,
                  const double              g,
                  const double              dt,
                  const ElasticModuli      &moduli,
                  const NonlocalParameters &material,
                  const bool                with_tangents)
  {
    const double S = moduli.S, B = moduli.B;
    const auto   I = dealii::unit_symmetric_tensor<3>();

    NonlocalPointUpdate r;
    r.J = dealii::determinant(F);

    // Steps 1-2 (60)-(61): trial elastic state; Ebar_tr = ln(B^e_tr) / 2 is the spatial Hencky strain.
    const Tensor2    Fe_tr = F * dealii::invert(Fp_n);
    const SymTensor2 Be_tr = dealii::symmetrize(Fe_tr * dealii::transpose(Fe_tr));
    const Eigen      e_B   = eigen(Be_tr);
    const auto       lnB   = log_from_eigen(e_B, with_tangents);
    const SymTensor2 E_tr  = 0.5 * lnB.value;

    // Step 3 (62), rotated to the spatial frame (71)-(72).
    const SymTensor2 TK_tr  = 2. * S * deviator(E_tr) + B * dealii::trace(E_tr) * I;
    const double     p_tr   = -dealii::trace(TK_tr) / 3.;
    const SymTensor2 s_tr   = deviator(TK_tr);
    const double     tau_tr = s_tr.norm() / std::sqrt(2.);

    // Step 4 (63) with the guards of the header: p = max(p_tr, 0), g_+ = max(g, 0).
    const bool   compressed = p_tr > 0.;
    const double p          = compressed ? p_tr : 0.;
    // g = 0 counts as flowing, so the tangent at the onset of flow carries d(mu)/dg (the right
    // derivative of max(g, 0)); otherwise Newton started from g = 0 cannot see the relaxation.
    const bool   flowing    = g >= 0.;
    const double g_plus     = flowing ? g : 0.;
    const double den        = p + S * dt * g_plus; // (56): taubar = taubar_tr p / den
    const double ratio      = den > 0. ? p / den : 1.; // taubar / taubar_tr = d taubar / d taubar_tr (79)_1

    r.p   = p;
    r.tau = ratio * tau_tr;
    // mu = taubar / p = taubar_tr / den stays defined at p = 0 when g > 0 (no shear strength).
    r.mu = den > 0. ? tau_tr / den : material.mu_s;
    // (57), (70): T^K = T^K_tr - sqrt(2) (taubar_tr - taubar) Nbar_tr = -p_tr 1 + ratio s_tr.
    const SymTensor2 TK = -p_tr * I + ratio * s_tr;
    r.T                 = TK / r.J;

    // Step 5 (64): Dbar^p = gamma_dot^p Nbar_tr / sqrt(2) = ((1 - ratio) / dt) s_tr / (2 S) since
    // dt gamma_dot^p = dt g mu = (taubar_tr - taubar) / S by (55)_1; F^e_{n+1} = exp(-dt Dbar^p) F^e_tr.
    r.gamma_dot_p = g_plus * r.mu;
    // dt Dbar^p = (1 - ratio) dev(Ebar_tr) is coaxial with B^e_tr: its exponential reuses the eigenvectors.
    std::array<double, 3> exp_minus_dt_Dp;
    const double          tr_E = dealii::trace(E_tr);
    for (unsigned int a = 0; a < 3; ++a)
      exp_minus_dt_Dp[a] = std::exp(-(1. - ratio) * (0.5 * std::log(e_B[a].first) - tr_E / 3.));
    const Tensor2 Fe = Tensor2(spectral_sum(e_B, exp_minus_dt_Dp)) * Fe_tr;
    r.Fp                   = dealii::invert(Fe) * F;

    // Step 6 (65).
    const auto gl = local_fluidity(p, r.mu, material);
    const auto xi = cooperativity_length(r.mu, material);
    r.g_loc       = gl.value;
    r.xi          = xi.value;
    const double xi2 = xi.value * xi.value;
    r.g_res          = (g - gl.value) / xi2;

    if (!with_tangents)
      return r;

    // Derivatives of g_res(taubar_tr, p, g) with mu = taubar_tr / den (equivalent to (87)-(89),
    // written in taubar_tr instead of taubar_{n+1}).
    const double dgres_dmu = den > 0. ? -gl.d_mu / xi2 - 2. * (g - gl.value) * xi.d_mu / (xi2 * xi.value) : 0.;
    const double dmu_dtau_tr = den > 0. ? 1. / den : 0.;
    const double dmu_dp      = den > 0. ? -r.mu / den : 0.;
    const double dmu_dg      = den > 0. && flowing ? -r.mu * S * dt / den : 0.;
    const double dgres_dtau_tr = dgres_dmu * dmu_dtau_tr;
    const double dgres_dp      = compressed ? -gl.d_p / xi2 + dgres_dmu * dmu_dp : 0.;
    // (89) plus the explicit 1/xi^2 that the transcription drops.
    r.dgres_dg = 1. / xi2 + dgres_dmu * dmu_dg;

    // (75): d taubar_tr / dEbar = sqrt(2) S Nbar_tr = S s_tr / taubar_tr (zero when taubar_tr = 0);
    // d p_tr / dEbar = -B 1 (77).
    const SymTensor2 dtau_tr_dE = tau_tr > 0. ? (S / tau_tr) * s_tr : SymTensor2();
    const SymTensor2 dgres_dE   = dgres_dtau_tr * dtau_tr_dE - B * dgres_dp * I;

    // (78) with taubar/taubar_tr = d taubar / d taubar_tr, so its N (x) N term vanishes:
    // D = 2 S ratio (I - 1 (x) 1 / 3) + B 1 (x) 1 - sqrt(2) B (d taubar / d p_tr) Nbar (x) 1, and
    // sqrt(2) (d taubar / d p_tr) Nbar = d ratio / dp * s_tr with d ratio / dp = S dt g_+ / den^2.
    const double dratio_dp = den > 0. && compressed ? S * dt * g_plus / (den * den) : 0.;
    const SymTensor4 D = 2. * S * ratio * (dealii::identity_tensor<3>() - dealii::outer_product(I, I) / 3.) +
                         B * dealii::outer_product(I, I) - B * dratio_dp * dealii::outer_product(s_tr, I);

    // (82)-(83): Lambda = dT/dg = (1/J) (d ratio / dg) s_tr, d ratio / dg = -p S dt / den^2.
    const double dratio_dg = den > 0. && flowing ? -p * S * dt / (den * den) : 0.;
    r.Lambda               = (dratio_dg / r.J) * s_tr;

    // (68)-(69) with dEbar = L : dB / 2 and dB_pq = dL_pk B_kq + B_pk dL_qk for dF = dL F:
    // C_ijkl = (1/J) sum_q (D : L)_ijkq B_ql - T_il delta_jk.
    const SymTensor4 DL = D * lnB.derivative;
    // (85)-(86): F_lq dg_res/dF_kq = ((dg_res/dEbar : L) B)_kl.
    const SymTensor2 Y = dgres_dE * lnB.derivative;
    r.dgres_dL         = Tensor2(Y) * Tensor2(Be_tr);
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              double v = 0.;
              for (unsigned int q = 0; q < 3; ++q)
                v += DL[i][j][k][q] * Be_tr[q][l];
              r.C[i][j][k][l] = v / r.J - (j == k ? r.T[i][l] : 0.);
            }
    return r;
  }
} // namespace granflow::rheology
