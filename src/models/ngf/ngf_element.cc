#include "models/ngf/ngf_element.h"

#include <cmath>
#include <limits>

namespace granflow::ngf
{
  using dealii::Tensor;
  using rheology::Tensor2;

  namespace
  {
    /// F and, per displacement-type dof 4 a + c, dF/dU and G = Grad(dx) at one point.
    struct PointKinematics
    {
      Tensor2              F, H; // H = F - 1, formed without cancellation
      double               J_minus_1 = 0.;
      std::vector<Tensor2> dF, G;  // indexed by element dof; entries of fluidity dofs stay zero
      double               r = 0.; // current radius (quad)
      Tensor<1, 3>         grad_theta, grad_u_r; // (quad)
    };

    void
    compute_kinematics(const Kinematics kinematics, const std::vector<double> &N,
                       const std::vector<Tensor<1, 3>> &dN, const double R, const ElementInput &in,
                       const bool with_modes, PointKinematics &k)
    {
      const unsigned int n = N.size();
      k.H                  = Tensor2();
      if (with_modes)
        {
          k.dF.assign(4 * n, Tensor2());
          k.G.assign(4 * n, Tensor2());
        }
      if (kinematics == Kinematics::brick)
        {
          for (unsigned int a = 0; a < n; ++a)
            k.H += dealii::outer_product(in.u[a], dN[a]);
          k.F         = dealii::unit_symmetric_tensor<3>() + k.H;
          k.J_minus_1 = rheology::determinant_minus_one(k.H);
          if (with_modes)
            for (unsigned int a = 0; a < n; ++a)
              for (unsigned int c = 0; c < 3; ++c)
                {
                  k.dF[4 * a + c][c] = dN[a];
                  k.G[4 * a + c]     = k.dF[4 * a + c];
                }
          return;
        }
      // Generalized axisymmetric with twist: rows (r, phi, z), columns (R, Theta, Z).
      double       u_r = 0.;
      Tensor<1, 3> grad_u_z;
      k.grad_u_r = k.grad_theta = Tensor<1, 3>();
      for (unsigned int a = 0; a < n; ++a)
        {
          u_r += N[a] * in.u[a][0];
          k.grad_u_r += in.u[a][0] * dN[a];
          grad_u_z += in.u[a][1] * dN[a];
          k.grad_theta += in.u[a][2] * dN[a];
        }
      const double        r = k.r = R + u_r;
      const Tensor<1, 3> &ur = k.grad_u_r, &th = k.grad_theta;
      k.H[0][0] = ur[0], k.H[0][1] = 0., k.H[0][2] = ur[2];
      k.H[1][0] = r * th[0], k.H[1][1] = u_r / R, k.H[1][2] = r * th[2]; // r / R - 1
      k.H[2][0] = grad_u_z[0], k.H[2][1] = 0., k.H[2][2] = grad_u_z[2];
      k.F         = dealii::unit_symmetric_tensor<3>() + k.H;
      k.J_minus_1 = rheology::determinant_minus_one(k.H);
      if (!with_modes)
        return;
      for (unsigned int a = 0; a < n; ++a)
        {
          // u_r: dx = N e_r, and e_r turns with the current theta field
          Tensor2 &Fr = k.dF[4 * a];
          Fr[0][0] = dN[a][0], Fr[0][2] = dN[a][2];
          Fr[1][0] = N[a] * th[0], Fr[1][1] = N[a] / R, Fr[1][2] = N[a] * th[2];
          k.G[4 * a] = Fr;
          // u_z: dx = N e_z
          Tensor2 &Fz = k.dF[4 * a + 1];
          Fz[2][0] = dN[a][0], Fz[2][2] = dN[a][2];
          k.G[4 * a + 1] = Fz;
          // theta: F changes in its phi row only, but dx = N r e_phi also turns the frame
          Tensor2 &Ft = k.dF[4 * a + 2];
          Ft[1][0] = r * dN[a][0], Ft[1][2] = r * dN[a][2];
          Tensor2 &Gt = k.G[4 * a + 2];
          Gt[0][0] = -N[a] * r * th[0], Gt[0][1] = -N[a] * r / R, Gt[0][2] = -N[a] * r * th[2];
          Gt[1][0] = dN[a][0] * r + N[a] * (1. + ur[0]);
          Gt[1][2] = dN[a][2] * r + N[a] * ur[2];
        }
    }

    /// d G_i / d U_j of the quad (zero for the brick): G of u_r depends on theta, G of theta on u_r
    /// and theta.
    Tensor2
    dG(const unsigned int i, const unsigned int j, const std::vector<double> &N,
       const std::vector<Tensor<1, 3>> &dN, const double R, const PointKinematics &k)
    {
      Tensor2            d;
      const unsigned int a = i / 4, ci = i % 4, b = j / 4, cj = j % 4;
      if (ci == 0 && cj == 2)
        {
          d[1][0] = N[a] * dN[b][0];
          d[1][2] = N[a] * dN[b][2];
        }
      else if (ci == 2 && cj == 0)
        {
          const double NN = N[a] * N[b];
          d[0][0]         = -NN * k.grad_theta[0];
          d[0][1]         = -NN / R;
          d[0][2]         = -NN * k.grad_theta[2];
          d[1][0]         = dN[a][0] * N[b] + N[a] * dN[b][0];
          d[1][2]         = dN[a][2] * N[b] + N[a] * dN[b][2];
        }
      else if (ci == 2 && cj == 2)
        {
          d[0][0] = -N[a] * k.r * dN[b][0];
          d[0][2] = -N[a] * k.r * dN[b][2];
        }
      return d;
    }

    double
    contract(const Tensor2 &A, const Tensor2 &B)
    {
      return dealii::scalar_product(A, B);
    }
  } // namespace

  void
  NonlocalElement::evaluate(const ElementShape &shape, const ElementInput &in,
                            const bool with_jacobian, ElementOutput &out) const
  {
    const unsigned int n_nodes      = in.u.size();
    const unsigned int n_dofs       = 4 * n_nodes;
    const unsigned int n_q          = shape.JxW.size();
    const bool         axisymmetric = kinematics == Kinematics::axisymmetric;
    out.residual.reinit(n_dofs);
    out.magnitude.reinit(n_dofs);
    if (with_jacobian)
      out.jacobian.reinit(n_dofs, n_dofs);
    out.points.resize(n_q);

    // F-bar: the volume change is taken at the centroid, F_bar = (J_0 / J)^{1/3} F.
    PointKinematics k0;
    compute_kinematics(kinematics, shape.N_centroid, shape.dN_dX_centroid, shape.R_centroid, in,
                       with_jacobian, k0);
    const double        J0 = 1. + k0.J_minus_1;
    std::vector<double> tr_dL0(n_dofs, 0.);
    if (with_jacobian && J0 > 0.)
      {
        const Tensor2 F0_inv = dealii::invert(k0.F);
        for (unsigned int i = 0; i < n_dofs; ++i)
          if (i % 4 != 3)
            tr_dL0[i] = dealii::trace(k0.dF[i] * F0_inv);
      }

    PointKinematics           k;
    std::vector<Tensor2>      H(n_dofs), dL(n_dofs), CdL(n_dofs);
    std::vector<double>       tr_dL(n_dofs);
    std::vector<Tensor<1, 3>> dN(n_nodes);
    for (unsigned int q = 0; q < n_q; ++q)
      {
        const auto  &N  = shape.N[q];
        const double R  = axisymmetric ? shape.R[q] : 1.;
        const double dV = shape.JxW[q] * R; // per radian for the quad
        compute_kinematics(kinematics, N, shape.dN_dX[q], R, in, true, k);
        double g = 0.;
        for (unsigned int a = 0; a < n_nodes; ++a)
          g += N[a] * in.g[a];
        const double J = 1. + k.J_minus_1;
        if (!(J > 0.) || !(J0 > 0.) || !std::isfinite(g))
          {
            out.residual = std::numeric_limits<double>::quiet_NaN();
            return;
          }
        // F_bar - 1 = H + c F with c = (J_0 / J)^{1/3} - 1, each formed without cancellation
        // (rheology::DisplacementGradient: the elastic strain keeps its relative precision).
        const double c = std::expm1((std::log1p(k0.J_minus_1) - std::log1p(k.J_minus_1)) / 3.);
        const rheology::DisplacementGradient F_bar{k.H + c * k.F};
        out.points[q] = local ? rheology::local_update(F_bar, in.Fp_n[q], in.dt, moduli, material,
                                                       with_jacobian)
                              : rheology::nonlocal_update(F_bar, in.Fp_n[q], g, in.dt, moduli,
                                                          material, with_jacobian);
        const auto   &pt     = out.points[q];
        const Tensor2 F_inv  = dealii::invert(k.F);
        const Tensor2 F_invT = dealii::transpose(F_inv);
        Tensor<1, 3>  grad_g;
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            dN[a] = F_invT * shape.dN_dX[q][a];
            grad_g += in.g[a] * dN[a];
          }
        const double  dv = J * dV;
        const Tensor2 T  = pt.T;

        // (35): r_i = int T : H_i dv - int b_0 . dx_i dV ; R_g^a = int (grad g . grad N^a + N^a
        // g_res) dv.
        for (unsigned int a = 0; a < n_nodes; ++a)
          {
            for (unsigned int c = 0; c < 3; ++c)
              {
                const unsigned int i = 4 * a + c;
                H[i]                 = k.G[i] * F_inv;
                double work          = in.body_force[c] * N[a]; // b . dx_i
                if (axisymmetric)
                  work = c == 0   ? in.body_force[0] * N[a]
                         : c == 1 ? in.body_force[2] * N[a]
                                  : in.body_force[1] * N[a] * k.r;
                out.residual[i] += contract(T, H[i]) * dv - work * dV;
                out.magnitude[i] += std::abs(contract(T, H[i]) * dv) + std::abs(work * dV);
              }
            // The local variant has no fluidity equation (its g rows are constrained, and its
            // update leaves xi unset): nothing to add there.
            if (local)
              continue;
            out.residual[4 * a + 3] += (grad_g * dN[a] + N[a] * pt.g_res) * dv;
            out.magnitude[4 * a + 3] +=
                (std::abs(grad_g * dN[a]) + N[a] * (std::abs(g) + pt.g_loc) / (pt.xi * pt.xi)) * dv;
          }
        if (!with_jacobian)
          continue;

        Tensor2 Q; // F-bar (de Souza Neto et al. 2008, (15.47)): Q = (1/3) C_ijmm - (2/3) T
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            Q[i][j] =
                (pt.C[i][j][0][0] + pt.C[i][j][1][1] + pt.C[i][j][2][2]) / 3. - 2. * T[i][j] / 3.;
        const double  tr_Gamma = dealii::trace(pt.dgres_dL);
        const Tensor2 Lambda   = pt.Lambda;
        for (unsigned int j = 0; j < n_dofs; ++j)
          if (j % 4 != 3)
            {
              dL[j]    = k.dF[j] * F_inv;
              tr_dL[j] = dealii::trace(dL[j]);
              CdL[j]   = dealii::double_contract<2, 0, 3, 1>(pt.C, dL[j]);
            }

        for (unsigned int i = 0; i < n_dofs; ++i)
          {
            const unsigned int a = i / 4;
            if (i % 4 != 3)
              {
                const double HQ = contract(H[i], Q);
                for (unsigned int j = 0; j < n_dofs; ++j)
                  {
                    if (j % 4 == 3)
                      {
                        // (80)-(82): d r_u / d g
                        out.jacobian(i, j) += contract(H[i], Lambda) * N[j / 4] * dv;
                        continue;
                      }
                    double v = contract(H[i], CdL[j]) + HQ * (tr_dL0[j] - tr_dL[j]);
                    if (axisymmetric)
                      v += contract(T, dG(i, j, N, shape.dN_dX[q], R, k) * F_inv);
                    out.jacobian(i, j) += v * dv;
                  }
                // the theta equation's body-force work b_phi N r depends on u_r
                if (axisymmetric && i % 4 == 2 && in.body_force[1] != 0.)
                  for (unsigned int b = 0; b < n_nodes; ++b)
                    out.jacobian(i, 4 * b) -= in.body_force[1] * N[a] * N[b] * dV;
              }
            else if (!local) // (no fluidity equation in the local variant, as above)
              for (unsigned int j = 0; j < n_dofs; ++j)
                {
                  const unsigned int b = j / 4;
                  if (j % 4 == 3)
                    {
                      // (88)-(89): d R_g / d g
                      out.jacobian(i, j) += (dN[a] * dN[b] + N[a] * pt.dgres_dg * N[b]) * dv;
                      continue;
                    }
                  // d R_g / d u (84) with the F-bar terms of d g_res (85)-(86)
                  const double geometric = -(grad_g * (dL[j] * dN[a])) - dN[a] * (dL[j] * grad_g) +
                                           (grad_g * dN[a]) * tr_dL[j];
                  const double reaction = contract(pt.dgres_dL, dL[j]) + pt.g_res * tr_dL[j] +
                                          tr_Gamma * (tr_dL0[j] - tr_dL[j]) / 3.;
                  out.jacobian(i, j) += (geometric + N[a] * reaction) * dv;
                }
          }
      }
  }
} // namespace granflow::ngf
