#include "models/ngf/ngf_element.h"

#include <cmath>
#include <limits>

namespace granflow::ngf
{
  using dealii::Tensor;
  using rheology::Tensor2;

  void
  NonlocalBrick::evaluate(const ElementShape &shape, const ElementInput &in, const bool with_jacobian,
                          ElementOutput &out) const
  {
    const unsigned int n_nodes = in.u.size();
    const unsigned int n_dofs  = 4 * n_nodes;
    const unsigned int n_q     = shape.JxW.size();
    out.residual.reinit(n_dofs);
    if (with_jacobian)
      out.jacobian.reinit(n_dofs, n_dofs);
    out.points.resize(n_q);

    const Tensor2 I = dealii::unit_symmetric_tensor<3>();
    // F-bar: the volume change is taken at the centroid, F_bar = (J_0 / J)^{1/3} F.
    Tensor2 F0 = I;
    for (unsigned int a = 0; a < n_nodes; ++a)
      F0 += dealii::outer_product(in.u[a], shape.dN_dX_centroid[a]);
    const double J0    = dealii::determinant(F0);
    out.J_centroid     = J0;
    const Tensor2 F0_invT = dealii::transpose(dealii::invert(F0));
    std::vector<Tensor<1, 3>> dN0(n_nodes); // spatial gradients at the centroid
    for (unsigned int a = 0; a < n_nodes; ++a)
      dN0[a] = F0_invT * shape.dN_dX_centroid[a];

    std::vector<Tensor<1, 3>> dN(n_nodes);
    for (unsigned int q = 0; q < n_q; ++q)
      {
        Tensor2 F = I;
        double  g = 0.;
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            F += dealii::outer_product(in.u[a], shape.dN_dX[q][a]);
            g += shape.N[q][a] * in.g[a];
          }
        const double J = dealii::determinant(F);
        if (!(J > 0.) || !(J0 > 0.) || !std::isfinite(g))
          {
            // an inverted or non-finite iterate: report a non-finite residual so the driver cuts the step
            out.residual = std::numeric_limits<double>::quiet_NaN();
            return;
          }
        const Tensor2 F_bar = std::cbrt(J0 / J) * F;
        const auto   &pt = out.points[q] = rheology::nonlocal_update(F_bar, in.Fp_n[q], g, in.dt, moduli, material,
                                                                      with_jacobian);
        const Tensor2 F_invT = dealii::transpose(dealii::invert(F));
        Tensor<1, 3>  grad_g;
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            dN[a] = F_invT * shape.dN_dX[q][a];
            grad_g += in.g[a] * dN[a];
          }
        const double   dv = J * shape.JxW[q];
        const Tensor2  T  = pt.T;
        const auto    &N  = shape.N[q];

        // (35): r_u^a = int T dN^a/dx dv - int N^a b_0 dV ; R_g^a = int (grad g . dN^a/dx + N^a g_res) dv.
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            const Tensor<1, 3> TdN = T * dN[a];
            for (unsigned int c = 0; c < 3; ++c)
              out.residual[4 * a + c] += TdN[c] * dv - N[a] * in.body_force[c] * shape.JxW[q];
            out.residual[4 * a + 3] += (grad_g * dN[a] + N[a] * pt.g_res) * dv;
          }
        if (!with_jacobian)
          continue;

        // F-bar tangent (de Souza Neto et al. 2008, (15.47)): dT_cj = C_cjel dL_el
        // + Q_cj (tr dL_0 - tr dL), Q = (1/3) C_ijmm - (2/3) T.
        Tensor2 Q;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            Q[i][j] = (pt.C[i][j][0][0] + pt.C[i][j][1][1] + pt.C[i][j][2][2]) / 3. - 2. * T[i][j] / 3.;
        const double tr_Gamma = dealii::trace(pt.dgres_dL);

        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            // CdN[c][e][l] = sum_j dN^a_j C_cjel (66); QdN[c] = sum_j Q_cj dN^a_j
            Tensor<3, 3> CdN;
            for (unsigned int c = 0; c < 3; ++c)
              for (unsigned int e = 0; e < 3; ++e)
                for (unsigned int l = 0; l < 3; ++l)
                  for (unsigned int j = 0; j < 3; ++j)
                    CdN[c][e][l] += dN[a][j] * pt.C[c][j][e][l];
            const Tensor<1, 3> QdN      = Q * dN[a];
            const Tensor<1, 3> LambdadN = Tensor2(pt.Lambda) * dN[a];
            const double       gdNa     = grad_g * dN[a];

            for (unsigned int b = 0; b < n_nodes; ++b)
              {
                const double dNadNb = dN[a] * dN[b];
                const double gdNb   = grad_g * dN[b];
                for (unsigned int e = 0; e < 3; ++e)
                  {
                    const double bar = dN0[b][e] - dN[b][e]; // tr dL_0 - tr dL for dof (b, e)
                    for (unsigned int c = 0; c < 3; ++c)
                      out.jacobian(4 * a + c, 4 * b + e) += (CdN[c][e] * dN[b] + QdN[c] * bar) * dv;
                    // d R_g / d u (84) with the F-bar terms of d g_res (85)-(86).
                    const double geometric = -grad_g[e] * dNadNb - dN[a][e] * gdNb + gdNa * dN[b][e];
                    double       Gamma_dN  = 0.;
                    for (unsigned int l = 0; l < 3; ++l)
                      Gamma_dN += pt.dgres_dL[e][l] * dN[b][l];
                    out.jacobian(4 * a + 3, 4 * b + e) +=
                      (geometric + N[a] * (Gamma_dN + pt.g_res * dN[b][e] + tr_Gamma * bar / 3.)) * dv;
                  }
                // (80)-(82): d r_u / d g
                for (unsigned int c = 0; c < 3; ++c)
                  out.jacobian(4 * a + c, 4 * b + 3) += LambdadN[c] * N[b] * dv;
                // (88)-(89): d R_g / d g
                out.jacobian(4 * a + 3, 4 * b + 3) += (dNadNb + N[a] * pt.dgres_dg * N[b]) * dv;
              }
          }
      }
  }
} // namespace granflow::ngf
