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
              e[a].first     = A[a][a];
              e[a].second    = dealii::Tensor<1, 3>();
              e[a].second[a] = 1.;
            }
          return e;
        }
      // A non-finite tensor (from a diverging Newton iterate) gives non-finite eigenpairs, so that
      // the caller sees a non-finite residual and cuts the step instead of stopping in deal.II.
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

    /// (ln(1 + a) - ln(1 + b)) / (a - b), and 1 / (1 + a) for a == b, without cancellation for
    /// close a, b.
    double
    log_divided_difference(const double a, const double b)
    {
      const double x = (a - b) / (1. + b);
      if (std::abs(x) < 1e-4) // series of log1p(x) / x, truncated at x^4 / 5 < 2e-17
        return (1. - x / 2. + x * x / 3. - x * x * x / 4.) / (1. + b);
      return std::log1p(x) / (a - b);
    }
  } // namespace

  namespace
  {
    /// ln(A) of a symmetric positive definite A from the eigenpairs (delta_a, n_a) of A - 1, and
    /// d ln(A)/dA if asked: ln(1 + delta_a) by log1p keeps its relative precision when A is near 1.
    SymmetricFunction
    log_from_eigen(const Eigen &e, const bool with_derivative)
    {
      std::array<double, 3> f;
      for (unsigned int a = 0; a < 3; ++a)
        f[a] = std::log1p(e[a].first);

      SymmetricFunction r;
      r.value = spectral_sum(e, f);
      if (!with_derivative)
        return r;
      // d f(A) : dA = sum_ab theta_ab (n_a . dA n_b) n_a (x) n_b, theta_aa = f'(lambda_a),
      // theta_ab = (f(lambda_a) - f(lambda_b)) / (lambda_a - lambda_b): the classical derivative of
      // an isotropic tensor function (de Souza Neto et al. 2008, Appendix A), smooth at equal
      // eigenvalues.
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
    return log_from_eigen(eigen(A - dealii::unit_symmetric_tensor<3>()), true);
  }

  double
  determinant_minus_one(const Tensor2 &H)
  {
    // det(1 + H) = 1 + I_1 + I_2 + I_3 with the principal invariants of H.
    const double I1 = dealii::trace(H);
    const double I2 = 0.5 * (I1 * I1 - dealii::trace(H * H));
    return I1 + I2 + dealii::determinant(H);
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

  namespace
  {
    /// Steps 1-3 (60)-(62) in the spatial frame: the trial elastic state.
    struct Trial
    {
      Tensor2           Fe;
      SymTensor2        Be, E, s; // B^e_tr, Ebar_tr = ln(B^e_tr) / 2, s_tr = dev T^K_tr
      Eigen             eigen_B;  // eigenvalues of B^e_tr - 1, eigenvectors of B^e_tr
      SymmetricFunction lnB;
      double            p = 0., tau = 0.; // pbar_tr, taubar_tr (72)
    };

    Trial
    trial_state(const DisplacementGradient &F, const Tensor2 &Fp_n, const ElasticModuli &moduli,
                const bool with_tangents)
    {
      // (60) without cancellation (DisplacementGradient): with P = F^p_n^{-1} - 1 =
      // -F^p_n^{-1} (F^p_n - 1), F^e_tr - 1 = (1 + H)(1 + P) - 1 and B^e_tr - 1 = He + He^T +
      // He He^T.
      const auto    I  = dealii::unit_symmetric_tensor<3>();
      const Tensor2 P  = -dealii::invert(Fp_n) * (Fp_n - I);
      const Tensor2 He = F.H + P + F.H * P;
      const auto    Be_minus_1 =
          dealii::symmetrize(He + dealii::transpose(He) + He * dealii::transpose(He));
      Trial t;
      t.Fe      = I + He;
      t.Be      = I + Be_minus_1;
      t.eigen_B = eigen(Be_minus_1);
      t.lnB     = log_from_eigen(t.eigen_B, with_tangents);
      t.E       = 0.5 * t.lnB.value;
      t.s       = 2. * moduli.S * deviator(t.E);
      t.p       = -moduli.B * dealii::trace(t.E);
      t.tau     = t.s.norm() / std::sqrt(2.);
      return t;
    }

    /// Step 5 (64): F^p_{n+1} = F^e_{n+1}^{-1} F with F^e_{n+1} = exp(-dt Dbar^p) F^e_tr and
    /// dt Dbar^p = (taubar_tr - taubar) Nbar_tr / (sqrt(2) S) = (1 - ratio) dev(Ebar_tr), coaxial
    /// with B^e_tr, so its exponential reuses the eigenvectors.
    Tensor2
    plastic_distortion(const Trial &t, const double ratio, const Tensor2 &F)
    {
      std::array<double, 3> f;
      const double          tr_E = dealii::trace(t.E);
      for (unsigned int a = 0; a < 3; ++a)
        f[a] = std::exp(-(1. - ratio) * (0.5 * std::log1p(t.eigen_B[a].first) - tr_E / 3.));
      return dealii::invert(Tensor2(spectral_sum(t.eigen_B, f)) * t.Fe) * F;
    }

    /// (68)-(69): C_ijkl = (1/J) sum_q (D : L)_ijkq B_ql - T_il delta_jk, with dEbar = L : dB / 2
    /// and dB_pq = dL_pk B_kq + B_pk dL_qk for dF = dL F.
    Tensor4
    spatial_tangent(const SymTensor4 &D, const Trial &t, const SymTensor2 &T, const double J)
    {
      const SymTensor4 DL = D * t.lnB.derivative;
      Tensor4          C;
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = 0; j < 3; ++j)
          for (unsigned int k = 0; k < 3; ++k)
            for (unsigned int l = 0; l < 3; ++l)
              {
                double v = 0.;
                for (unsigned int q = 0; q < 3; ++q)
                  v += DL[i][j][k][q] * t.Be[q][l];
                C[i][j][k][l] = v / J - (j == k ? T[i][l] : 0.);
              }
      return C;
    }
  } // namespace

  NonlocalPointUpdate
  nonlocal_update(const Tensor2 &F, const Tensor2 &Fp_n, const double g, const double dt,
                  const ElasticModuli &moduli, const NonlocalParameters &material,
                  const bool with_tangents)
  {
    return nonlocal_update(DisplacementGradient{F - dealii::unit_symmetric_tensor<3>()}, Fp_n, g,
                           dt, moduli, material, with_tangents);
  }

  NonlocalPointUpdate
  nonlocal_update(const DisplacementGradient &F, const Tensor2 &Fp_n, const double g,
                  const double dt, const ElasticModuli &moduli, const NonlocalParameters &material,
                  const bool with_tangents)
  {
    const double S = moduli.S, B = moduli.B;
    const auto   I = dealii::unit_symmetric_tensor<3>();

    NonlocalPointUpdate r;
    r.J = 1. + determinant_minus_one(F.H);

    // Steps 1-3 (60)-(62), rotated to the spatial frame (71)-(72).
    const Trial       trial = trial_state(F, Fp_n, moduli, with_tangents);
    const double      p_tr = trial.p, tau_tr = trial.tau;
    const SymTensor2 &s_tr = trial.s;

    // Step 4 (63) with the guards of the header: p = max(p_tr, 0), g_+ = max(g, 0).
    const bool   compressed = p_tr > 0.;
    const double p          = compressed ? p_tr : 0.;
    // g = 0 counts as flowing, so the tangent at the onset of flow carries d(mu)/dg (the right
    // derivative of max(g, 0)); otherwise Newton started from g = 0 cannot see the relaxation.
    const bool   flowing = g >= 0.;
    const double g_plus  = flowing ? g : 0.;
    const double den     = p + S * dt * g_plus; // (56): taubar = taubar_tr p / den
    const double ratio =
        den > 0. ? p / den : 1.; // taubar / taubar_tr = d taubar / d taubar_tr (79)_1

    r.p   = p;
    r.tau = ratio * tau_tr;
    // mu = taubar / p = taubar_tr / den stays defined at p = 0 when g > 0 (no shear strength).
    r.mu = den > 0. ? tau_tr / den : material.mu_s;
    // (57), (70): T^K = T^K_tr - sqrt(2) (taubar_tr - taubar) Nbar_tr = -p_tr 1 + ratio s_tr.
    r.T = (-p_tr * I + ratio * s_tr) / r.J;

    // Step 5 (64); dt gamma_dot^p = dt g mu = (taubar_tr - taubar) / S by (55)_1.
    r.gamma_dot_p = g_plus * r.mu;
    r.Fp          = plastic_distortion(trial, ratio, F.F());

    // Step 6 (65).
    const auto gl    = local_fluidity(p, r.mu, material);
    const auto xi    = cooperativity_length(r.mu, material);
    r.g_loc          = gl.value;
    r.xi             = xi.value;
    const double xi2 = xi.value * xi.value;
    r.g_res          = (g - gl.value) / xi2;

    if (!with_tangents)
      return r;

    // Derivatives of g_res(taubar_tr, p, g) with mu = taubar_tr / den (equivalent to (87)-(89),
    // written in taubar_tr instead of taubar_{n+1}).
    const double dgres_dmu =
        den > 0. ? -gl.d_mu / xi2 - 2. * (g - gl.value) * xi.d_mu / (xi2 * xi.value) : 0.;
    const double dmu_dtau_tr   = den > 0. ? 1. / den : 0.;
    const double dmu_dp        = den > 0. ? -r.mu / den : 0.;
    const double dmu_dg        = den > 0. && flowing ? -r.mu * S * dt / den : 0.;
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
    const double     dratio_dp = den > 0. && compressed ? S * dt * g_plus / (den * den) : 0.;
    const SymTensor4 D =
        2. * S * ratio * (dealii::identity_tensor<3>() - dealii::outer_product(I, I) / 3.) +
        B * dealii::outer_product(I, I) - B * dratio_dp * dealii::outer_product(s_tr, I);

    // (82)-(83): Lambda = dT/dg = (1/J) (d ratio / dg) s_tr, d ratio / dg = -p S dt / den^2.
    const double dratio_dg = den > 0. && flowing ? -p * S * dt / (den * den) : 0.;
    r.Lambda               = (dratio_dg / r.J) * s_tr;

    r.C = spatial_tangent(D, trial, r.T, r.J);
    // (85)-(86): F_lq dg_res/dF_kq = ((dg_res/dEbar : L) B)_kl.
    r.dgres_dL = Tensor2(dgres_dE * trial.lnB.derivative) * Tensor2(trial.Be);
    return r;
  }

  NonlocalPointUpdate
  local_update(const Tensor2 &F, const Tensor2 &Fp_n, const double dt, const ElasticModuli &moduli,
               const NonlocalParameters &material, const bool with_tangents)
  {
    return local_update(DisplacementGradient{F - dealii::unit_symmetric_tensor<3>()}, Fp_n, dt,
                        moduli, material, with_tangents);
  }

  NonlocalPointUpdate
  local_update(const DisplacementGradient &F, const Tensor2 &Fp_n, const double dt,
               const ElasticModuli &moduli, const NonlocalParameters &material,
               const bool with_tangents)
  {
    const double S = moduli.S, B = moduli.B;
    const auto   I = dealii::unit_symmetric_tensor<3>();

    NonlocalPointUpdate r;
    r.J                = 1. + determinant_minus_one(F.H);
    const Trial  trial = trial_state(F, Fp_n, moduli, with_tangents);
    const double p = std::max(trial.p, 0.), tau_tr = trial.tau;
    const double mu_s = material.mu_s;
    // (1): gamma_dot^p = sqrt(p / (rho_s d^2)) (mu - mu_s) / b for mu > mu_s. With (55)_1,
    // taubar + S dt gamma_dot^p(taubar / p) = taubar_tr is linear in taubar:
    // taubar = (taubar_tr + k mu_s p) / (1 + k), k = S dt / (b d sqrt(rho_s p)).
    const bool   flowing = p > 0. && tau_tr > mu_s * p;
    const double k =
        flowing ? S * dt / (material.b * material.d * std::sqrt(material.rho_s * p)) : 0.;
    const double tau   = flowing ? (tau_tr + k * mu_s * p) / (1. + k) : tau_tr;
    const double ratio = tau_tr > 0. ? tau / tau_tr : 1.;

    r.p           = p;
    r.tau         = tau;
    r.mu          = p > 0. ? tau / p : 0.;
    r.T           = (-trial.p * I + ratio * trial.s) / r.J;
    r.gamma_dot_p = flowing ? (tau_tr - tau) / (S * dt) : 0.;
    r.g_loc       = flowing ? r.gamma_dot_p / r.mu : 0.; // g = g_loc (22)
    r.Fp          = plastic_distortion(trial, ratio, F.F());
    if (!with_tangents)
      return r;

    // D = dT^K/dEbar = B 1 (x) 1 + 2 S ratio I_dev + s_tr (x) d ratio/dEbar, with
    // d ratio / d taubar_tr = -k mu_s p / ((1 + k) taubar_tr^2), d taubar_tr / dEbar = S s_tr /
    // taubar_tr, d taubar / dp = (k / 2) (mu_s + taubar / p) / (1 + k) (dk/dp = -k / (2 p)), dp /
    // dEbar = -B 1.
    SymTensor4 D =
        2. * S * ratio * (dealii::identity_tensor<3>() - dealii::outer_product(I, I) / 3.) +
        B * dealii::outer_product(I, I);
    if (flowing)
      {
        const double dratio_dtau_tr = -k * mu_s * p / ((1. + k) * tau_tr * tau_tr);
        const double dratio_dp      = 0.5 * k * (mu_s + tau / p) / ((1. + k) * tau_tr);
        D += dratio_dtau_tr * (S / tau_tr) * dealii::outer_product(trial.s, trial.s) -
             B * dratio_dp * dealii::outer_product(trial.s, I);
      }
    r.C = spatial_tangent(D, trial, r.T, r.J);
    return r;
  }
} // namespace granflow::rheology
