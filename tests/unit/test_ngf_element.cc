// Unit test of the (u, g) brick of the ngf model (src/models/ngf/ngf_element.h): every block of the
// element Jacobian (K_uu with its F-bar terms, K_ug, K_gu, K_gg; Henann (66)-(89)) against
// fourth-order central differences of the element residual (35), on a distorted brick in a
// finitely deformed, plastically pre-strained, flowing state.
#include "models/ngf/ngf_element.h"

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

#include <gtest/gtest.h>

#include <random>

namespace
{
  using namespace granflow;
  using dealii::Tensor;

  // a sheared, non-affine brick of about one grain diameter (1 mm); FE_Q(1) node a is vertex a
  const std::vector<dealii::Point<3>> vertices = {{0, 0, 0},          {1.1e-3, 0, 0.1e-3}, {0.1e-3, 0.9e-3, 0},
                                       {1.0e-3, 1e-3, 0},  {0, 0, 1e-3},        {1e-3, 0.1e-3, 1.1e-3},
                                       {0, 1e-3, 0.9e-3},  {1.2e-3, 1.1e-3, 1e-3}};

  ngf::ElementShape
  distorted_brick_shape()
  {
    dealii::Triangulation<3> tria;
    dealii::GridGenerator::general_cell(tria, vertices);
    dealii::FE_Q<3>        fe(1);
    dealii::QGauss<3>      quadrature(2);
    dealii::FEValues<3>    values(fe, quadrature, dealii::update_values | dealii::update_gradients |
                                                    dealii::update_JxW_values);
    dealii::FEValues<3>    centroid(fe, dealii::Quadrature<3>(dealii::Point<3>(0.5, 0.5, 0.5)),
                                    dealii::update_gradients);
    values.reinit(tria.begin_active());
    centroid.reinit(tria.begin_active());
    ngf::ElementShape s;
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        s.JxW.push_back(values.JxW(q));
        s.N.emplace_back();
        s.dN_dX.emplace_back();
        for (unsigned int a = 0; a < 8; ++a)
          {
            s.N.back().push_back(values.shape_value(a, q));
            s.dN_dX.back().push_back(values.shape_grad(a, q));
          }
      }
    for (unsigned int a = 0; a < 8; ++a)
      s.dN_dX_centroid.push_back(centroid.shape_grad(a, 0));
    return s;
  }

  TEST(NgfElement, JacobianMatchesFiniteDifferencesOfTheResidual)
  {
    const rheology::NonlocalParameters material{};
    const rheology::ElasticModuli      moduli{};
    const ngf::NonlocalBrick           brick(moduli, material);
    const ngf::ElementShape            shape = distorted_brick_shape();

    std::mt19937                           rng(3);
    std::uniform_real_distribution<double> u01(-1., 1.);
    ngf::ElementInput                      in;
    in.dt         = 2e-3;
    in.body_force = Tensor<1, 3>({0., 0., 0.62 * 2450. * 9.81});
    // F = F^e F^p with a plastic shear of 0.4, an elastic shear of 4e-4 and an elastic compression of
    // 1e-4 (mu_tr ~ 0.6 > mu_s for g dt = 4e-4), plus a non-affine perturbation of the nodes.
    rheology::Tensor2 Fp = dealii::unit_symmetric_tensor<3>();
    Fp[0][2]             = 0.4;
    Fp[1][0]             = 0.1;
    Fp[1][2]             = 0.04; // det = 1
    in.Fp_n.assign(shape.JxW.size(), Fp);
    rheology::SymTensor2 Ee = -3e-5 * dealii::unit_symmetric_tensor<3>();
    Ee[0][2]                = 4e-4;
    const rheology::Tensor2 F = rheology::Tensor2(rheology::exp_sym(Ee)) * Fp;
    for (unsigned int a = 0; a < 8; ++a)
      {
        const dealii::Point<3> &X = vertices[a];
        Tensor<1, 3>           u = (F - rheology::Tensor2(dealii::unit_symmetric_tensor<3>())) * X;
        for (unsigned int c = 0; c < 3; ++c)
          u[c] += 5e-9 * u01(rng);
        in.u.push_back(u);
        in.g.push_back(0.2 + 0.1 * u01(rng));
      }

    ngf::ElementOutput out;
    brick.evaluate(shape, in, true, out);
    bool above = false;
    for (const auto &pt : out.points)
      above |= pt.mu > material.mu_s && pt.g_loc > 0.;
    ASSERT_TRUE(above) << "the state should flow above mu_s somewhere";

    const double w[4] = {1., -8., 8., -1.}, h[4] = {-2., -1., 1., 2.};
    double       worst[2][2] = {{0, 0}, {0, 0}}, scale[2][2] = {{0, 0}, {0, 0}};
    for (unsigned int j = 0; j < 32; ++j)
      {
        const double step = j % 4 == 3 ? 1e-5 : 1e-11; // g ~ 0.2 1/s; u: elastic strain changes of 1e-8
        dealii::Vector<double> fd(32);
        for (int n = 0; n < 4; ++n)
          {
            ngf::ElementInput p = in;
            if (j % 4 == 3)
              p.g[j / 4] += h[n] * step;
            else
              p.u[j / 4][j % 4] += h[n] * step;
            ngf::ElementOutput o;
            brick.evaluate(shape, p, false, o);
            fd.add(w[n] / (12. * step), o.residual);
          }
        for (unsigned int i = 0; i < 32; ++i)
          {
            const int bi = i % 4 == 3, bj = j % 4 == 3;
            worst[bi][bj] = std::max(worst[bi][bj], std::abs(out.jacobian(i, j) - fd[i]));
            scale[bi][bj] = std::max(scale[bi][bj], std::abs(fd[i]));
          }
      }
    const char *names[2][2] = {{"K_uu", "K_ug"}, {"K_gu", "K_gg"}};
    for (int bi = 0; bi < 2; ++bi)
      for (int bj = 0; bj < 2; ++bj)
        {
          EXPECT_GT(scale[bi][bj], 0.) << names[bi][bj];
          EXPECT_LT(worst[bi][bj], 1e-6 * scale[bi][bj]) << names[bi][bj] << ": max error " << worst[bi][bj]
                                                          << " of max entry " << scale[bi][bj];
        }
  }
} // namespace
