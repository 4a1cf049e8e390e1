// Unit tests of the Drucker-Prager kernel src/rheology/drucker_prager.h against
// Daviet & Bertails-Descoubes 2016: Definition 1 and Properties 1-2 (chi), (7) and (16) (cones and
// their projections, the four cases of the proof of Theorem 3), Theorems 1-3 (f_AC, f_DS) and
// Corollary 1 (f_FB, Bi = 0). Every reference is computed here, independently of the kernel:
// projections in the meridian half-plane (x_N, ||x_T||) from the nearest points of the boundary
// pieces (checked against dense sampling), membership of DP(mu, Bi) by the disjunctive form (13)
// and by the tensor form (3), complementary pairs of K_1 from its Jordan frame.
// Random samples use a fixed-seed std::mt19937, so every run sees the same samples.
#include "rheology/drucker_prager.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  using namespace granflow::rheology;

  template <std::size_t n> using Vec = std::array<double, n>;

  template <int d> using Mat = std::array<std::array<double, d>, d>;

  template <int d> struct Dim
  {
    static constexpr int         dim = d;
    static constexpr std::size_t n   = n_sym<d>;
  };

  // Relative tolerances: "zero" is rounding of O(1e-16) amplified by a few operations; "nonzero" is
  // far below the smallest residual that the violations generated below (of relative size >= 1e-3)
  // leave, and far above rounding.
  constexpr double rel_tol     = 1e-10;
  constexpr double vi_tol      = 1e-12;
  constexpr double nonzero_tol = 1e-8;

  // Parameter sets (mu, Bi): cohesive Drucker-Prager, steep and shallow cones, nearly Bingham (the
  // apex of the cone is far away, -Bi/mu = -1e9), Bingham (mu = 0), Coulomb (Bi = 0), both zero.
  struct Params
  {
    double mu, Bi;
  };
  const std::vector<Params> all_params = {{0.5, 1.}, {1.3, 0.2}, {3., 0.5}, {0.05, 2.}, {1e-9, 1.},
                                          {0., 1.},  {0.7, 0.},  {2.5, 0.}, {0., 0.}};

  // ----- small vector algebra, here so that the references do not reuse the kernel's helpers
  double
  sq(const double a)
  {
    return a * a;
  }

  template <std::size_t n>
  double
  dot(const Vec<n> &a, const Vec<n> &b)
  {
    double s = 0.;
    for (std::size_t i = 0; i < n; ++i)
      s += a[i] * b[i];
    return s;
  }

  template <std::size_t n>
  double
  len(const Vec<n> &a)
  {
    return std::sqrt(dot(a, a));
  }

  template <std::size_t n>
  double
  len_T(const Vec<n> &a)
  {
    double s = 0.;
    for (std::size_t i = 1; i < n; ++i)
      s += a[i] * a[i];
    return std::sqrt(s);
  }

  /// alpha a + beta b
  template <std::size_t n>
  Vec<n>
  lin(const double alpha, const Vec<n> &a, const double beta, const Vec<n> &b)
  {
    Vec<n> c{};
    for (std::size_t i = 0; i < n; ++i)
      c[i] = alpha * a[i] + beta * b[i];
    return c;
  }

  template <std::size_t n>
  double
  dist(const Vec<n> &a, const Vec<n> &b)
  {
    return len(lin(1., a, -1., b));
  }

  /// (N; r e) for a unit tangential direction e (e[0] = 0).
  template <std::size_t n>
  Vec<n>
  from_NT(const double N, const double r, const Vec<n> &e)
  {
    Vec<n> x{};
    x[0] = N;
    for (std::size_t i = 1; i < n; ++i)
      x[i] = r * e[i];
    return x;
  }

  /// "(x_N; x_T)" for failure messages.
  template <std::size_t n>
  std::string
  str(const Vec<n> &x)
  {
    std::ostringstream os;
    os.precision(17);
    os << '(' << x[0] << ';';
    for (std::size_t i = 1; i < n; ++i)
      os << ' ' << x[i];
    os << ')';
    return os.str();
  }

  class Sampler
  {
  public:
    explicit Sampler(const unsigned int seed)
        : rng(seed)
    {
    }

    double
    uniform(const double a, const double b)
    {
      return std::uniform_real_distribution<double>(a, b)(rng);
    }

    bool
    coin(const double p = 0.5)
    {
      return uniform(0., 1.) < p;
    }

    int
    pick(const int k)
    {
      return std::uniform_int_distribution<int>(0, k - 1)(rng);
    }

    template <std::size_t n>
    Vec<n>
    vec(const double a, const double b)
    {
      Vec<n> x{};
      for (double &v : x)
        v = uniform(a, b);
      return x;
    }

    /// Uniformly distributed unit vector of the tangential subspace (component 0 is zero).
    template <std::size_t n>
    Vec<n>
    direction()
    {
      std::normal_distribution<double> g;
      Vec<n>                           e{};
      double                           r = 0.;
      while (r < 1e-3)
        {
          for (std::size_t i = 1; i < n; ++i)
            e[i] = g(rng);
          r = len_T(e);
        }
      for (std::size_t i = 1; i < n; ++i)
        e[i] /= r;
      return e;
    }

    /// A unit tangential vector orthogonal to the unit tangential vector e.
    template <std::size_t n>
    Vec<n>
    perpendicular(const Vec<n> &e)
    {
      Vec<n> f{};
      double r = 0.;
      while (r < 1e-2)
        {
          f = direction<n>();
          f = lin(1., f, -dot(f, e), e);
          r = len(f);
        }
      for (double &v : f)
        v /= r;
      return f;
    }

  private:
    std::mt19937 rng;
  };

  /// Random point of [-3, 3]^n, sometimes snapped onto the axis (x_T = 0) or the plane x_N = 0.
  template <std::size_t n>
  Vec<n>
  random_point(Sampler &rng)
  {
    Vec<n> x = rng.vec<n>(-3., 3.);
    if (rng.coin(0.2))
      for (std::size_t i = 1; i < n; ++i)
        x[i] = 0.;
    if (rng.coin(0.2))
      x[0] = 0.;
    return x;
  }

  // ----- tensors as plain d x d arrays: Tr, Dev, : and |.| computed here, not with deal.II
  // operators

  template <int d>
  Mat<d>
  to_mat(const dealii::SymmetricTensor<2, d> &s)
  {
    Mat<d> m{};
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        m[i][j] = s[i][j];
    return m;
  }

  template <int d>
  dealii::SymmetricTensor<2, d>
  from_mat(const Mat<d> &m)
  {
    dealii::SymmetricTensor<2, d> s;
    for (int i = 0; i < d; ++i)
      for (int j = i; j < d; ++j)
        s[i][j] = m[i][j];
    return s;
  }

  template <int d>
  double
  trace(const Mat<d> &m)
  {
    double t = 0.;
    for (int i = 0; i < d; ++i)
      t += m[i][i];
    return t;
  }

  template <int d>
  Mat<d>
  dev(const Mat<d> &m)
  {
    Mat<d>       r = m;
    const double t = trace<d>(m) / d;
    for (int i = 0; i < d; ++i)
      r[i][i] -= t;
    return r;
  }

  template <int d>
  double
  contract(const Mat<d> &a, const Mat<d> &b)
  {
    double s = 0.;
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        s += a[i][j] * b[i][j];
    return s;
  }

  /// Daviet Section 2: |sigma| = sqrt(sigma : sigma / 2).
  template <int d>
  double
  tnorm(const Mat<d> &a)
  {
    return std::sqrt(0.5 * contract<d>(a, a));
  }

  /// alpha a + beta b
  template <int d>
  Mat<d>
  tlin(const double alpha, const Mat<d> &a, const double beta, const Mat<d> &b)
  {
    Mat<d> c{};
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        c[i][j] = alpha * a[i][j] + beta * b[i][j];
    return c;
  }

  template <int d>
  Mat<d>
  identity()
  {
    Mat<d> m{};
    for (int i = 0; i < d; ++i)
      m[i][i] = 1.;
    return m;
  }

  /// Definition 1 written out entry by entry.
  template <int d>
  Mat<d>
  chi_by_hand(const Vec<n_sym<d>> &x)
  {
    Mat<d> m{};
    if constexpr (d == 2)
      {
        const double a = x[0], b = x[1], c = x[2];
        m[0] = {{b + a, c}};
        m[1] = {{c, -b + a}};
      }
    else
      {
        const double a = x[0], b = x[1], c = x[2], dd = x[3], e = x[4], f = x[5];
        const double r3 = std::sqrt(3.), s = std::sqrt(2.) / std::sqrt(3.) * a;
        m[0] = {{b - c / r3 + s, dd, e}};
        m[1] = {{dd, -b - c / r3 + s, f}};
        m[2] = {{e, f, 2. * c / r3 + s}};
      }
    return m;
  }

  // ----- reference projection onto K_{mu,Bi}, (16)

  enum Case
  {
    interior      = 0,
    conical_face  = 1,
    base_disc     = 2,
    circular_edge = 3 // for Bi = 0: the apex
  };

  struct Meridian
  {
    double N, r;
  };

  /// Projection of (N, r), r >= 0, onto the meridian section {N >= 0, |r| <= Bi + mu N} of
  /// K_{mu,Bi}; the lower ray r = -(Bi + mu s) is never nearer than its mirror image, so the
  /// section is R = conv{(0, 0), (0, Bi)} + cone{(1, 0), (1, mu)}. Candidates: the nearest points
  /// of the base segment {0} x [0, Bi] and of the ray {(s, Bi + mu s), s >= 0}. The projection is
  /// the candidate P with (X - P).(Z - P) <= 0 on R, i.e. on the two vertices and the two recession
  /// directions. (Comparing the two distances instead is ill-conditioned: near a tie the candidates
  /// can be sqrt(eps) apart while their distances agree to rounding.)
  Meridian
  project_meridian(const double N, const double r, const double mu, const double Bi)
  {
    if (N >= 0. && r <= Bi + mu * N)
      return {N, r};
    const Meridian base{0., std::clamp(r, 0., Bi)};
    const double   s = std::max(0., (N + mu * (r - Bi)) / (1. + mu * mu));
    const Meridian face{s, Bi + mu * s};
    const auto     violation = [&](const Meridian &p) {
      const double a = N - p.N, b = r - p.r; // X - P
      return std::max(
              {a * (0. - p.N) + b * (0. - p.r), a * (0. - p.N) + b * (Bi - p.r), a, a + b * mu});
    };
    return violation(base) <= violation(face) ? base : face;
  }

  /// The set is invariant under rotations of x_T, so the projection keeps the direction of x_T.
  template <std::size_t n>
  Vec<n>
  reference_projection(const Vec<n> &x, const double mu, const double Bi)
  {
    const double   r = len_T(x);
    const Meridian p = project_meridian(x[0], r, mu, Bi);
    Vec<n>         y{};
    y[0] = p.N;
    if (r > 0.)
      for (std::size_t i = 1; i < n; ++i)
        y[i] = p.r * x[i] / r;
    return y;
  }

  template <std::size_t n>
  bool
  in_truncated_cone(const Vec<n> &x, const double mu, const double Bi, const double tol)
  {
    return x[0] >= -tol && len_T(x) <= Bi + mu * x[0] + tol;
  }

  /// Which case of the proof of Theorem 3 the projection p of x falls in.
  template <std::size_t n>
  Case
  classify(const Vec<n> &x, const Vec<n> &p, const double Bi, const double tol)
  {
    if (dist(x, p) <= tol)
      return interior;
    if (p[0] > tol)
      return conical_face;
    if (len_T(p) < Bi - tol)
      return base_disc;
    return circular_edge;
  }

  template <std::size_t n> struct CaseSample
  {
    Vec<n> x, p; // p: the projection of x, known by construction
  };

  /// x = p + a normal of K_{mu,Bi} at p, p chosen in the given case: x projects onto p.
  template <std::size_t n>
  CaseSample<n>
  sample_case(Sampler &rng, const Case kase, const double mu, const double Bi)
  {
    const Vec<n> e = rng.direction<n>();
    const double c = 1. / std::sqrt(1. + mu * mu); // outward normal of the face: c (-mu, 1)
    Meridian     x{}, p{};
    switch (kase)
      {
      case interior:
        p   = {rng.uniform(0., 3.), 0.};
        p.r = rng.uniform(0., 1.) * (Bi + mu * p.N);
        x   = p;
        break;
      case conical_face:
        {
          p              = {rng.uniform(0.01, 3.), 0.};
          p.r            = Bi + mu * p.N;
          const double t = rng.uniform(0.01, 3.);
          x              = {p.N - t * mu * c, p.r + t * c};
          break;
        }
      case base_disc:
        p = {0., rng.uniform(0., 0.999) * Bi};
        x = {-rng.uniform(0.01, 3.), p.r};
        break;
      case circular_edge:
        {
          // normal cone at the edge (or apex): spanned by (-1, 0) and c (-mu, 1)
          p              = {0., Bi};
          const double a = rng.uniform(0.01, 3.), b = rng.uniform(0.01, 3.);
          x = {-a - b * mu * c, Bi + b * c};
          break;
        }
      }
    return {from_NT(x.N, x.r, e), from_NT(p.N, p.r, e)};
  }

  // ----- DP(mu, Bi) in the disjunctive form (13) and in the tensor form (3)

  template <std::size_t n> struct Pair
  {
    Vec<n> lambda, D;
  };

  /// Theorem 1, (13), with a tolerance on every equality and inequality.
  template <std::size_t n>
  bool
  in_DP_13(const Vec<n> &lambda, const Vec<n> &D, const double mu, const double Bi,
           const double tol)
  {
    const double lN = lambda[0], DN = D[0];
    if (lN < -tol || DN < -tol || (lN > tol && DN > tol)) // (13c)
      return false;
    const double kappa = Bi + mu * lN;
    const double tD    = len_T(D);
    if (tD > tol) // (13a)
      {
        double s = 0.;
        for (std::size_t i = 1; i < n; ++i)
          s += sq(lambda[i] + kappa * D[i] / tD);
        return std::sqrt(s) <= tol;
      }
    return len_T(lambda) <= kappa + tol; // (13b)
  }

  /// (3a)-(3c) on the tensors, with Tr, Dev and |.| computed on the d x d arrays.
  template <int d>
  bool
  in_DP_3(const Mat<d> &lambda, const Mat<d> &D, const double mu, const double Bi, const double tol)
  {
    const double p = trace<d>(lambda) / d, trD = trace<d>(D);
    if (p < -tol || trD < -tol || (p > tol && trD > tol)) // (3c)
      return false;
    const double kappa = Bi + mu * trace<d>(lambda) / std::sqrt(2. * d);
    const Mat<d> devL = dev<d>(lambda), devD = dev<d>(D);
    const double nD = tnorm<d>(devD);
    if (nD > tol) // (3a)
      return tnorm<d>(tlin<d>(1., devL, kappa / nD, devD)) <= tol;
    return tnorm<d>(devL) <= kappa + tol; // (3b)
  }

  enum class Normal
  {
    pressed,  // lambda_N > 0, D_N = 0
    dilating, // lambda_N = 0, D_N > 0
    free      // lambda_N = 0, D_N = 0
  };

  Normal
  random_normal(Sampler &rng)
  {
    return static_cast<Normal>(rng.pick(3));
  }

  void
  set_normal(Sampler &rng, const Normal normal, double &lambda_N, double &D_N)
  {
    lambda_N = normal == Normal::pressed ? rng.uniform(0.05, 3.) : 0.;
    D_N      = normal == Normal::dilating ? rng.uniform(0.05, 3.) : 0.;
  }

  /// A pair of DP(mu, Bi) built from (13): flowing (D_T != 0, lambda_T = -kappa D_T / ||D_T||) or
  /// rigid (D_T = 0, ||lambda_T|| <= kappa, also on the yield surface and at zero shear stress).
  template <std::size_t n>
  Pair<n>
  dp_pair(Sampler &rng, const bool flowing, const Normal normal, const double mu, const double Bi)
  {
    Pair<n> q{};
    set_normal(rng, normal, q.lambda[0], q.D[0]);
    const double kappa = Bi + mu * q.lambda[0];
    const Vec<n> e     = rng.direction<n>();
    if (flowing)
      {
        const double rD = rng.uniform(0.01, 3.);
        for (std::size_t i = 1; i < n; ++i)
          {
            q.D[i]      = rD * e[i];
            q.lambda[i] = -kappa * e[i];
          }
      }
    else
      {
        const int    k = rng.pick(3);
        const double u = k == 0 ? rng.uniform(0., 1.) : (k == 1 ? 1. : 0.);
        for (std::size_t i = 1; i < n; ++i)
          q.lambda[i] = u * kappa * e[i];
      }
    return q;
  }

  template <std::size_t n>
  Pair<n>
  random_dp_pair(Sampler &rng, const double mu, const double Bi)
  {
    const bool   flowing = rng.coin();
    const Normal normal  = random_normal(rng);
    return dp_pair<n>(rng, flowing, normal, mu, Bi);
  }

  enum Violation
  {
    lambda_N_negative,
    D_N_negative,
    both_normal_positive,
    tangent_rotated,      // flowing, ||lambda_T|| = kappa but not opposite to D_T
    tangent_wrong_length, // flowing, lambda_T opposite to D_T but ||lambda_T|| != kappa
    rigid_overstressed,   // D_T = 0, ||lambda_T|| > kappa
    tangent_along_D,      // flowing, lambda_T along +D_T
    n_violations
  };

  /// A pair that violates (13) in exactly the given way.
  template <std::size_t n>
  Pair<n>
  off_dp_pair(Sampler &rng, const Violation v, const double mu, const double Bi)
  {
    // The tangential violations need kappa > 0: with Bi = 0, press the material.
    const Normal normal = Bi == 0. ? Normal::pressed : random_normal(rng);
    switch (v)
      {
      case lambda_N_negative:
        {
          Pair<n> q   = random_dp_pair<n>(rng, mu, Bi);
          q.lambda[0] = -rng.uniform(0.05, 2.);
          return q;
        }
      case D_N_negative:
        {
          Pair<n> q = random_dp_pair<n>(rng, mu, Bi);
          q.D[0]    = -rng.uniform(0.05, 2.);
          return q;
        }
      case both_normal_positive:
        {
          Pair<n> q = dp_pair<n>(rng, rng.coin(), Normal::pressed, mu, Bi);
          q.D[0]    = rng.uniform(0.05, 2.);
          return q;
        }
      case tangent_rotated:
      case tangent_wrong_length:
        {
          Pair<n>      q     = dp_pair<n>(rng, true, normal, mu, Bi);
          const double kappa = Bi + mu * q.lambda[0];
          Vec<n>       e     = q.D;
          e[0]               = 0.;
          e                  = lin(1. / len_T(e), e, 0., e);
          if (kappa == 0.) // mu = Bi = 0: any nonzero shear stress violates (13a)
            {
              const Vec<n> f = rng.direction<n>();
              const double r = rng.uniform(0.05, 1.);
              for (std::size_t i = 1; i < n; ++i)
                q.lambda[i] = r * f[i];
              return q;
            }
          if (v == tangent_wrong_length)
            {
              const double u = rng.coin() ? rng.uniform(0., 0.95) : rng.uniform(1.05, 2.);
              for (std::size_t i = 1; i < n; ++i)
                q.lambda[i] = -u * kappa * e[i];
              return q;
            }
          const Vec<n> f     = rng.perpendicular(e);
          const double theta = rng.uniform(0.1, std::acos(-1.));
          for (std::size_t i = 1; i < n; ++i)
            q.lambda[i] = kappa * (-std::cos(theta) * e[i] + std::sin(theta) * f[i]);
          return q;
        }
      case rigid_overstressed:
        {
          Pair<n>      q     = dp_pair<n>(rng, false, random_normal(rng), mu, Bi);
          const double kappa = Bi + mu * q.lambda[0];
          const Vec<n> e     = rng.direction<n>();
          const double r     = kappa > 0. ? rng.uniform(1.05, 3.) * kappa : rng.uniform(0.05, 1.);
          for (std::size_t i = 1; i < n; ++i)
            q.lambda[i] = r * e[i];
          return q;
        }
      case tangent_along_D:
        {
          Pair<n>      q     = dp_pair<n>(rng, true, random_normal(rng), mu, Bi);
          const double kappa = Bi + mu * q.lambda[0];
          const double r     = kappa > 0. ? kappa : rng.uniform(0.05, 1.);
          const double tD    = len_T(q.D);
          for (std::size_t i = 1; i < n; ++i)
            q.lambda[i] = r * q.D[i] / tD;
          return q;
        }
      default:
        break;
      }
    ADD_FAILURE() << "unknown violation";
    return {};
  }

  /// Random pair with some parts snapped onto the structures of (13): zero normal parts,
  /// zero D_T, lambda_T on the yield surface and opposite to D_T, ...
  template <std::size_t n>
  Pair<n>
  snapped_pair(Sampler &rng, const double mu, const double Bi)
  {
    Pair<n> q{rng.vec<n>(-2., 2.), rng.vec<n>(-2., 2.)};
    if (rng.coin())
      q.lambda[0] = std::abs(q.lambda[0]);
    if (rng.coin())
      q.D[0] = std::abs(q.D[0]);
    if (rng.coin(0.4))
      q.lambda[0] = 0.;
    if (rng.coin(0.4))
      q.D[0] = 0.;
    if (rng.coin(0.4))
      for (std::size_t i = 1; i < n; ++i)
        q.D[i] = 0.;
    const double kappa = Bi + mu * q.lambda[0];
    const double tD = len_T(q.D), tL = len_T(q.lambda);
    if (rng.coin(0.6) && kappa >= 0.)
      {
        const double scale = rng.coin() ? 1. : rng.uniform(0., 1.5);
        for (std::size_t i = 1; i < n; ++i)
          q.lambda[i] = tD > 0. ? -scale * kappa * q.D[i] / tD : scale * kappa * q.lambda[i] / tL;
      }
    return q;
  }

  /// One third each: pairs of DP(mu, Bi), pairs violating (13) on purpose, snapped random pairs.
  template <std::size_t n>
  Pair<n>
  mixed_pair(Sampler &rng, const double mu, const double Bi)
  {
    switch (rng.pick(3))
      {
      case 0:
        return random_dp_pair<n>(rng, mu, Bi);
      case 1:
        return off_dp_pair<n>(rng, static_cast<Violation>(rng.pick(n_violations)), mu, Bi);
      default:
        return snapped_pair<n>(rng, mu, Bi);
      }
  }

  template <std::size_t n>
  double
  pair_scale(const Pair<n> &q, const double Bi)
  {
    return 1. + len(q.lambda) + len(q.D) + Bi;
  }

  // ----- Jordan algebra of K_1: x o y = (x.y; x_0 y_T + y_0 x_T)

  template <std::size_t n>
  Vec<n>
  jordan(const Vec<n> &x, const Vec<n> &y)
  {
    Vec<n> z{};
    z[0] = dot(x, y);
    for (std::size_t i = 1; i < n; ++i)
      z[i] = x[0] * y[i] + y[0] * x[i];
    return z;
  }

  /// Jordan frame of K_1 along the unit tangential direction e: u1 = (1; -e)/2, u2 = (1; e)/2.
  template <std::size_t n>
  std::array<Vec<n>, 2>
  jordan_frame(const Vec<n> &e)
  {
    Vec<n> u1{}, u2{};
    u1[0] = u2[0] = 0.5;
    for (std::size_t i = 1; i < n; ++i)
      {
        u1[i] = -0.5 * e[i];
        u2[i] = 0.5 * e[i];
      }
    return {{u1, u2}};
  }

  const std::vector<std::array<double, 2>> ac_xis = {{{1., 1.}}, {{0.1, 3.7}}, {{25., 0.02}}};
  const std::vector<double>                ds_xis = {1., 0.05, 40.};

  /// |f| <= zero_tol if expected_zero, |f| > nonzero_threshold (clearly away from rounding)
  /// otherwise.
  ::testing::AssertionResult
  zero_iff(const bool expected_zero, const double f, const double zero_tol,
           const double nonzero_threshold)
  {
    if (expected_zero ? f <= zero_tol : f > nonzero_threshold)
      return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << (expected_zero ? "expected zero: |f| = " : "expected nonzero: |f| = ") << f
           << (expected_zero ? " > " : " <= ") << (expected_zero ? zero_tol : nonzero_threshold);
  }

  template <typename T> class DruckerPrager : public ::testing::Test
  {
  };

  using Dims = ::testing::Types<Dim<2>, Dim<3>>;
  TYPED_TEST_SUITE(DruckerPrager, Dims);

  // ================================================================================ chi,
  // Section 3.2.2

  TYPED_TEST(DruckerPrager, ChiIsDefinition1)
  {
    constexpr int         d = TypeParam::dim;
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(11);
    for (int k = 0; k < 2000; ++k)
      {
        const Vec<n> x = rng.vec<n>(-3., 3.);
        const Mat<d> a = to_mat<d>(chi<d>(x)), b = chi_by_hand<d>(x);
        for (int i = 0; i < d; ++i)
          for (int j = 0; j < d; ++j)
            ASSERT_NEAR(a[i][j], b[i][j], rel_tol * (1. + len(x))) << i << j;
      }
  }

  TYPED_TEST(DruckerPrager, ChiProperty1Orthonormal)
  {
    constexpr int         d = TypeParam::dim;
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(12);
    for (int k = 0; k < 3000; ++k)
      {
        const Vec<n> x = rng.vec<n>(-3., 3.), y = rng.vec<n>(-3., 3.);
        const Mat<d> X = to_mat<d>(chi<d>(x)), Y = to_mat<d>(chi<d>(y));
        const double scale = len(x) * len(y);
        // (11): x.y = <chi(x), chi(y)> = chi(x):chi(y)/2
        ASSERT_NEAR(dot(x, y), 0.5 * contract<d>(X, Y), rel_tol * scale);
        ASSERT_NEAR(len(x), tnorm<d>(X), rel_tol * len(x));
        // chi is linear
        const Mat<d> Z = to_mat<d>(chi<d>(lin(2.5, x, -1., y)));
        ASSERT_LE(tnorm<d>(tlin<d>(1., Z, -1., tlin<d>(2.5, X, -1., Y))),
                  rel_tol * (len(x) + len(y)));
        // chi^{-1}(chi(x)) = x, and chi(chi^{-1}(S)) = S for an arbitrary symmetric S
        ASSERT_LE(dist(chi_inverse<d>(chi<d>(x)), x), rel_tol * len(x));
        Mat<d> S{};
        for (int i = 0; i < d; ++i)
          for (int j = i; j < d; ++j)
            S[i][j] = S[j][i] = rng.uniform(-3., 3.);
        const Mat<d> S2 = to_mat<d>(chi<d>(chi_inverse<d>(from_mat<d>(S))));
        ASSERT_LE(tnorm<d>(tlin<d>(1., S2, -1., S)), rel_tol * tnorm<d>(S));
      }
  }

  TYPED_TEST(DruckerPrager, ChiProperty2TraceAndDeviator)
  {
    constexpr int         d = TypeParam::dim;
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(13);
    for (int k = 0; k < 3000; ++k)
      {
        const Vec<n> x = rng.vec<n>(-3., 3.);
        const Mat<d> X = to_mat<d>(chi<d>(x));
        ASSERT_NEAR(trace<d>(X) / std::sqrt(2. * d), x[0], rel_tol * len(x)); // (12a)
        ASSERT_NEAR(tnorm<d>(dev<d>(X)), len_T(x), rel_tol * len(x));         // (12b)
        // and the kernel's own norms agree with the definitions
        ASSERT_NEAR(tensor_norm<d>(chi<d>(x)), len(x), rel_tol * len(x));
        ASSERT_NEAR(norm_T(x), len_T(x), rel_tol * len(x));
        ASSERT_NEAR(granflow::rheology::norm(x), len(x), rel_tol * len(x));
      }
  }

  // ===================================================================== projections, (7) and (16)

  TYPED_TEST(DruckerPrager, ReferenceProjectionIsNearestSampledPoint)
  {
    // The meridian reference against brute force: dense sampling of the boundary pieces.
    Sampler rng(21);
    for (const Params &P : all_params)
      {
        if (P.mu < 1e-6 && P.mu > 0.)
          continue; // the face ray would need a sampling length of 1/mu
        const int    K    = 20000;
        const double Smax = 20.;
        for (int k = 0; k < 200; ++k)
          {
            const double   N = rng.uniform(-4., 4.), r = rng.uniform(0., 4.);
            const Meridian p     = project_meridian(N, r, P.mu, P.Bi);
            const double   d_ref = std::hypot(p.N - N, p.r - r);
            ASSERT_GE(p.N, 0.);
            ASSERT_LE(p.r, P.Bi + P.mu * p.N + 1e-14);
            if (N >= 0. && r <= P.Bi + P.mu * N)
              {
                ASSERT_EQ(d_ref, 0.);
                continue;
              }
            double d_min = 1e300;
            for (int i = 0; i <= K; ++i)
              {
                const double s = Smax * i / K, b = P.Bi * i / K;
                d_min = std::min(d_min, std::hypot(s - N, P.Bi + P.mu * s - r));
                d_min = std::min(d_min, std::hypot(N, b - r));
              }
            const double h = Smax * std::sqrt(1. + P.mu * P.mu) / K + P.Bi / K;
            ASSERT_LE(d_ref, d_min + 1e-12) << "mu " << P.mu << " Bi " << P.Bi;
            ASSERT_LE(d_min, d_ref + h) << "mu " << P.mu << " Bi " << P.Bi;
          }
      }
  }

  TYPED_TEST(DruckerPrager, ProjectionOntoCone)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(22);
    for (const double mu : {0., 0.3, 1., 2.5, 1e-9})
      for (int k = 0; k < 4000; ++k)
        {
          const Vec<n> x =
              k < 1000 ? random_point<n>(rng)
                       : sample_case<n>(rng, static_cast<Case>(k % 3 == 2 ? 3 : k % 3), mu, 0.).x;
          const Vec<n> p     = project_onto_cone(x, mu);
          const double scale = 1. + len(x);
          ASSERT_TRUE(in_truncated_cone(p, mu, 0., vi_tol * scale)) << "mu " << mu;
          ASSERT_LE(dist(p, reference_projection(x, mu, 0.)), rel_tol * scale)
              << "mu " << mu << " x " << str(x) << " p " << str(p) << " ref "
              << str(reference_projection(x, mu, 0.));
          ASSERT_LE(dist(project_onto_cone(p, mu), p), vi_tol * scale);
          // Moreau: x - p lies in the polar cone -K_{1/mu} and is orthogonal to p.
          const Vec<n> q = lin(1., x, -1., p);
          ASSERT_LE(mu * len_T(q), -q[0] + vi_tol * scale);
          ASSERT_NEAR(dot(q, p), 0., vi_tol * scale * scale);
          for (int j = 0; j < 10; ++j)
            {
              const Vec<n> z = sample_case<n>(rng, interior, mu, 0.).x;
              ASSERT_LE(dot(q, lin(1., z, -1., p)), vi_tol * scale * (1. + len(z)));
            }
        }
  }

  TYPED_TEST(DruckerPrager, ProjectionOntoTruncatedCone)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(23);
    for (const Params &P : all_params)
      {
        std::array<int, 4> count{};
        const int          per_case = 1500;
        for (int k = 0; k < 4 * per_case + 3000; ++k)
          {
            const bool random = k >= 4 * per_case;
            const Case kase   = static_cast<Case>(k % 4);
            if (!random && kase == base_disc && P.Bi == 0.)
              continue; // no base: the edge construction covers the apex
            CaseSample<n> c{};
            if (random)
              c.x = random_point<n>(rng);
            else
              c = sample_case<n>(rng, kase, P.mu, P.Bi);
            const Vec<n> &x     = c.x;
            const Vec<n>  p     = project_onto_truncated_cone(x, P.mu, P.Bi);
            const double  scale = 1. + len(x) + P.Bi;
            SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi << " sample " << k);
            ASSERT_TRUE(in_truncated_cone(p, P.mu, P.Bi, vi_tol * scale));
            ASSERT_LE(dist(p, reference_projection(x, P.mu, P.Bi)), rel_tol * scale);
            const Case found = classify(x, p, P.Bi, rel_tol * scale);
            ++count[found];
            if (!random)
              {
                ASSERT_LE(dist(p, c.p), rel_tol * scale);
                ASSERT_EQ(found, kase);
              }
            ASSERT_LE(dist(project_onto_truncated_cone(p, P.mu, P.Bi), p), vi_tol * scale);
            // variational inequality: (x - p).(z - p) <= 0 for every z of the set
            for (int j = 0; j < 10; ++j)
              {
                const Vec<n> z = sample_case<n>(rng, interior, P.mu, P.Bi).x;
                ASSERT_LE(dot(lin(1., x, -1., p), lin(1., z, -1., p)),
                          vi_tol * scale * (1. + len(z)));
              }
          }
        SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi);
        EXPECT_GE(count[interior], per_case);
        EXPECT_GE(count[conical_face], per_case);
        EXPECT_GE(count[circular_edge], per_case);
        if (P.Bi > 0.)
          EXPECT_GE(count[base_disc], per_case);
        else
          EXPECT_EQ(count[base_disc], 0);
      }
  }

  TYPED_TEST(DruckerPrager, DeSaxceChangeOfVariable)
  {
    // (17) and (47a)-(47c): D_hat is in K_{1/mu} iff D_N >= 0, on its boundary iff D_N = 0.
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(24);
    for (const double mu : {0.3, 1., 2.5})
      for (int k = 0; k < 2000; ++k)
        {
          Vec<n> D = rng.vec<n>(-2., 2.);
          if (k % 3 == 0)
            D[0] = 0.;
          const Vec<n> h = de_saxce(D, mu);
          ASSERT_NEAR(h[0], D[0] + mu * len_T(D), rel_tol * (1. + len(D)));
          for (std::size_t i = 1; i < n; ++i)
            ASSERT_EQ(h[i], D[i]);
          const double slack = h[0] / mu - len_T(h); // >= 0 iff h in K_{1/mu}
          if (D[0] == 0.)
            ASSERT_NEAR(slack, 0., rel_tol * (1. + len(D)) / mu);
          else
            ASSERT_EQ(slack > 0., D[0] > 0.);
        }
  }

  // =============================================================== Theorems 1-3 and Corollary 1

  TYPED_TEST(DruckerPrager, ResidualValuesAreDefinitions2And3)
  {
    // Values, not only zero sets, on arbitrary pairs: Definition 2 with Pi_{R+} and the projection
    // onto the ball B(kappa(lambda_N)) (radius clipped at 0), and (18) with (17) and the reference
    // projection onto K_{mu,Bi}.
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(35);
    for (const Params &P : all_params)
      for (int k = 0; k < 2000; ++k)
        {
          const Pair<n> q     = mixed_pair<n>(rng, P.mu, P.Bi);
          const double  scale = pair_scale(q, P.Bi);
          SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi << " sample " << k);
          for (const auto &xi : ac_xis)
            {
              Vec<n> f{};
              f[0]               = std::max(0., q.lambda[0] - xi[0] * q.D[0]) - q.lambda[0];
              const double kappa = std::max(0., P.Bi + P.mu * q.lambda[0]);
              Vec<n>       y{};
              for (std::size_t i = 1; i < n; ++i)
                y[i] = q.lambda[i] - xi[1] * q.D[i];
              const double ty = len_T(y);
              for (std::size_t i = 1; i < n; ++i)
                f[i] = (ty > kappa ? kappa * y[i] / ty : y[i]) - q.lambda[i];
              ASSERT_LE(dist(f_AC(q.lambda, q.D, P.mu, P.Bi, xi[0], xi[1]), f),
                        rel_tol * scale * (1. + xi[0] + xi[1]));
            }
          for (const double xi : ds_xis)
            {
              Vec<n> D_hat = q.D;
              D_hat[0] += P.mu * len_T(q.D);
              const Vec<n> f =
                  lin(1., reference_projection(lin(1., q.lambda, -xi, D_hat), P.mu, P.Bi), -1.,
                      q.lambda);
              ASSERT_LE(dist(f_DS(q.lambda, q.D, P.mu, P.Bi, xi), f), rel_tol * scale * (1. + xi));
            }
        }
  }

  TYPED_TEST(DruckerPrager, ResidualsVanishOnDP)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(31);
    for (const Params &P : all_params)
      {
        std::array<int, 2> flowing_dilating{}; // per flowing / rigid
        for (int k = 0; k < 3000; ++k)
          {
            const bool    flowing = k % 2 == 0;
            const Normal  normal  = static_cast<Normal>((k / 2) % 3);
            const Pair<n> q       = dp_pair<n>(rng, flowing, normal, P.mu, P.Bi);
            const double  scale   = pair_scale(q, P.Bi);
            SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi << " sample " << k);
            ASSERT_TRUE(in_DP_13(q.lambda, q.D, P.mu, P.Bi, rel_tol * scale));
            if (normal == Normal::dilating)
              ++flowing_dilating[flowing ? 0 : 1];
            for (const auto &xi : ac_xis)
              ASSERT_LE(len(f_AC(q.lambda, q.D, P.mu, P.Bi, xi[0], xi[1])),
                        rel_tol * scale * (1. + xi[0] + xi[1]));
            for (const double xi : ds_xis)
              ASSERT_LE(len(f_DS(q.lambda, q.D, P.mu, P.Bi, xi)), rel_tol * scale * (1. + xi));
            if (P.Bi == 0.)
              {
                ASSERT_LE(len(f_FB(q.lambda, q.D, P.mu)), rel_tol * scale) << "f_FB";
              }
          }
        EXPECT_GT(flowing_dilating[0], 0);
        EXPECT_GT(flowing_dilating[1], 0);
      }
  }

  TYPED_TEST(DruckerPrager, ResidualsNonzeroOffDP)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(32);
    for (const Params &P : all_params)
      for (int k = 0; k < 3500; ++k)
        {
          const Violation v     = static_cast<Violation>(k % n_violations);
          const Pair<n>   q     = off_dp_pair<n>(rng, v, P.mu, P.Bi);
          const double    scale = pair_scale(q, P.Bi);
          SCOPED_TRACE(testing::Message()
                       << "mu " << P.mu << " Bi " << P.Bi << " violation " << v << " sample " << k
                       << " lambda " << str(q.lambda) << " D " << str(q.D));
          ASSERT_FALSE(in_DP_13(q.lambda, q.D, P.mu, P.Bi, 1e-3));
          for (const auto &xi : ac_xis)
            ASSERT_GT(len(f_AC(q.lambda, q.D, P.mu, P.Bi, xi[0], xi[1])), nonzero_tol * scale);
          for (const double xi : ds_xis)
            ASSERT_GT(len(f_DS(q.lambda, q.D, P.mu, P.Bi, xi)), nonzero_tol * scale);
          if (P.Bi == 0.)
            {
              ASSERT_GT(len(f_FB(q.lambda, q.D, P.mu)), nonzero_tol * scale) << "f_FB";
            }
        }
  }

  TYPED_TEST(DruckerPrager, ZeroSetsAgreeWith13)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(33);
    for (const Params &P : all_params)
      {
        std::array<int, 2> count{};
        for (int k = 0; k < 6000; ++k)
          {
            const Pair<n> q     = mixed_pair<n>(rng, P.mu, P.Bi);
            const double  scale = pair_scale(q, P.Bi);
            const bool    in_dp = in_DP_13(q.lambda, q.D, P.mu, P.Bi, 1e-12 * scale);
            ++count[in_dp];
            SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi << " sample " << k
                                            << " in DP " << in_dp);
            // f == 0 iff (13); and off DP the residual is clearly away from rounding.
            for (const auto &xi : ac_xis)
              ASSERT_TRUE(zero_iff(in_dp, len(f_AC(q.lambda, q.D, P.mu, P.Bi, xi[0], xi[1])),
                                   rel_tol * scale * (1. + xi[0] + xi[1]), nonzero_tol * scale))
                  << "f_AC, xi " << xi[0] << ' ' << xi[1];
            for (const double xi : ds_xis)
              ASSERT_TRUE(zero_iff(in_dp, len(f_DS(q.lambda, q.D, P.mu, P.Bi, xi)),
                                   rel_tol * scale * (1. + xi), nonzero_tol * scale))
                  << "f_DS, xi " << xi;
            if (P.Bi == 0.)
              {
                ASSERT_TRUE(zero_iff(in_dp, len(f_FB(q.lambda, q.D, P.mu)), rel_tol * scale,
                                     nonzero_tol * scale))
                    << "f_FB";
              }
          }
        EXPECT_GE(count[0], 2000) << "mu " << P.mu << " Bi " << P.Bi;
        EXPECT_GE(count[1], 1500) << "mu " << P.mu << " Bi " << P.Bi;
      }
  }

  TYPED_TEST(DruckerPrager, TensorForm3AgreesWithVectorForm13)
  {
    constexpr int         d = TypeParam::dim;
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(34);
    for (const Params &P : all_params)
      {
        // (i) the same pairs seen as tensors through chi
        std::array<int, 2> count{};
        for (int k = 0; k < 3000; ++k)
          {
            const Pair<n> q     = mixed_pair<n>(rng, P.mu, P.Bi);
            const double  tol   = 1e-12 * pair_scale(q, P.Bi);
            const bool    in_dp = in_DP_13(q.lambda, q.D, P.mu, P.Bi, tol);
            ++count[in_dp];
            ASSERT_EQ(
                in_DP_3<d>(to_mat<d>(chi<d>(q.lambda)), to_mat<d>(chi<d>(q.D)), P.mu, P.Bi, tol),
                in_dp)
                << "mu " << P.mu << " Bi " << P.Bi << " sample " << k;
          }
        EXPECT_GE(count[0], 500);
        EXPECT_GE(count[1], 500);

        // (ii) pairs built on tensors from (1)-(2): lambda = p I - tau, D = D(u); the kernel sees
        // chi^{-1} of them. With wrong_sign, tau is along -Dev D, the wrong way round.
        for (int k = 0; k < 3000; ++k)
          {
            const bool   flowing = k % 2 == 0, wrong_sign = k % 5 == 0 && flowing;
            const Normal normal = static_cast<Normal>((k / 2) % 3);
            double       p = 0., trD = 0.;
            set_normal(rng, normal, p, trD);
            Mat<d> D{};
            if (flowing)
              for (int i = 0; i < d; ++i)
                for (int j = i; j < d; ++j)
                  D[i][j] = D[j][i] = rng.uniform(-2., 2.);
            D                  = tlin<d>(1., dev<d>(D), trD / d, identity<d>());
            const double kappa = P.Bi + P.mu * std::sqrt(d / 2.) * p; // kappa(sqrt(d/2) p)
            Mat<d>       tau{};
            if (flowing)
              {
                // with kappa = 0, any nonzero shear stress is wrong
                const double size =
                    wrong_sign ? -(kappa > 0. ? kappa : rng.uniform(0.05, 1.)) : kappa;
                tau = tlin<d>(size / tnorm<d>(dev<d>(D)), dev<d>(D), 0., D);
              }
            else
              {
                for (int i = 0; i < d; ++i)
                  for (int j = i; j < d; ++j)
                    tau[i][j] = tau[j][i] = rng.uniform(-1., 1.);
                tau = dev<d>(tau);
                tau = tlin<d>(rng.uniform(0., 1.) * kappa / tnorm<d>(tau), tau, 0., tau);
              }
            const Mat<d> lambda = tlin<d>(p, identity<d>(), -1., tau);
            const Vec<n> l      = chi_inverse<d>(from_mat<d>(lambda)),
                         g      = chi_inverse<d>(from_mat<d>(D));
            const double scale  = 1. + len(l) + len(g) + P.Bi;
            SCOPED_TRACE(testing::Message() << "mu " << P.mu << " Bi " << P.Bi << " sample " << k);
            ASSERT_EQ(in_DP_3<d>(lambda, D, P.mu, P.Bi, 1e-12 * scale), !wrong_sign);
            ASSERT_EQ(in_DP_13(l, g, P.mu, P.Bi, 1e-12 * scale), !wrong_sign);
            const double f_ac = len(f_AC(l, g, P.mu, P.Bi)), f_ds = len(f_DS(l, g, P.mu, P.Bi));
            ASSERT_TRUE(zero_iff(!wrong_sign, f_ac, rel_tol * scale, nonzero_tol * scale))
                << "f_AC";
            ASSERT_TRUE(zero_iff(!wrong_sign, f_ds, rel_tol * scale, nonzero_tol * scale))
                << "f_DS";
          }
      }
  }

  // ============================================================ Fischer-Burmeister on K_1

  TYPED_TEST(DruckerPrager, FischerBurmeisterZeroIffComplementary)
  {
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(41);
    for (int k = 0; k < 6000; ++k)
      {
        const auto [u1, u2] = jordan_frame(rng.direction<n>());
        // spectral coefficients in (0.01, 3), and some of them snapped to zero
        std::array<double, 3> c{}, c0{};
        for (std::size_t i = 0; i < 3; ++i)
          {
            c[i]  = rng.uniform(0.01, 3.);
            c0[i] = rng.coin(0.3) ? 0. : c[i];
          }
        const bool first = rng.coin();
        Vec<n>     x{}, y{};
        bool       complementary = true;
        switch (k % 8)
          {
          case 0: // the two boundary rays of one frame, a, b >= 0
            x = lin(c0[0], u1, 0., u1);
            y = lin(c0[1], u2, 0., u2);
            break;
          case 1: // interior and zero
            x = lin(c[0], u1, c[1], u2);
            break;
          case 2: // zero and boundary
            y = lin(c[0], u2, 0., u2);
            break;
          case 3: // the same ray: x.y > 0
            x             = lin(c[0], u1, 0., u1);
            y             = lin(c[1], u1, 0., u1);
            complementary = false;
            break;
          case 4: // interior and nonzero: x.y > 0
            x             = lin(c[0], u1, c[1], u2);
            y             = lin(c[2], first ? u1 : u2, 0., u1);
            complementary = false;
            break;
          case 5: // x outside K_1 (a negative spectral value), y in K_1, possibly 0
            x             = lin(-c[0], u1, c0[1], u2);
            y             = lin(c0[2], u1, 0., u1);
            complementary = false;
            break;
          case 6: // y outside K_1
            x             = lin(c[0], u1, 0., u1);
            y             = lin(c[1], u2, -c[2], u1);
            complementary = false;
            break;
          default: // random
            x             = rng.vec<n>(-2., 2.);
            y             = rng.vec<n>(-2., 2.);
            complementary = false;
            break;
          }
        if (rng.coin())
          std::swap(x, y);
        const double scale = 1. + len(x) + len(y);
        const double f     = len(fischer_burmeister_K1(x, y));
        SCOPED_TRACE(testing::Message() << "sample " << k);
        // the predicate itself, independent of the construction
        const bool predicate = len_T(x) <= x[0] + 1e-12 * scale &&
                               len_T(y) <= y[0] + 1e-12 * scale &&
                               std::abs(dot(x, y)) <= 1e-12 * scale * scale;
        ASSERT_EQ(predicate, complementary);
        ASSERT_TRUE(zero_iff(complementary, f, rel_tol * scale, nonzero_tol * scale));
        ASSERT_LE(dist(fischer_burmeister_K1(x, y), fischer_burmeister_K1(y, x)), rel_tol * scale);
      }
  }

  TYPED_TEST(DruckerPrager, FischerBurmeisterIsJordanSquareRoot)
  {
    // phi = x + y - w with w in K_1 and w o w = x o x + y o y (w is the unique such root).
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(42);
    for (int k = 0; k < 4000; ++k)
      {
        const Vec<n> x = rng.vec<n>(-2., 2.), y = k % 4 == 0 ? Vec<n>{} : rng.vec<n>(-2., 2.);
        const Vec<n> w     = lin(1., lin(1., x, 1., y), -1., fischer_burmeister_K1(x, y));
        const double scale = 1. + dot(x, x) + dot(y, y);
        ASSERT_LE(len_T(w), w[0] + rel_tol * std::sqrt(scale));
        ASSERT_LE(dist(jordan(w, w), lin(1., jordan(x, x), 1., jordan(y, y))), rel_tol * scale);
      }
  }

  TYPED_TEST(DruckerPrager, FischerBurmeisterOfDPIsCorollary1)
  {
    // f_FB(lambda, D) = 0 iff K_mu ∋ lambda ⊥ D_hat ∈ K_{1/mu} (Corollary 1), checked on the
    // complementarity predicate computed here, for mu > 0.
    constexpr std::size_t n = TypeParam::n;
    Sampler               rng(43);
    for (const double mu : {0.3, 1., 2.5})
      {
        std::array<int, 2> count{};
        for (int k = 0; k < 4000; ++k)
          {
            const Pair<n> q     = mixed_pair<n>(rng, mu, 0.);
            const Vec<n>  h     = de_saxce(q.D, mu);
            const double  scale = pair_scale(q, 0.);
            const double  tol   = 1e-12 * scale;
            const bool    soccp = len_T(q.lambda) <= mu * q.lambda[0] + tol &&
                               mu * len_T(h) <= h[0] + tol &&
                               std::abs(dot(q.lambda, h)) <= tol * scale;
            ASSERT_EQ(soccp, in_DP_13(q.lambda, q.D, mu, 0., tol))
                << "mu " << mu << " sample " << k;
            ++count[soccp];
            const double f = len(f_FB(q.lambda, q.D, mu));
            ASSERT_TRUE(zero_iff(soccp, f, rel_tol * scale, nonzero_tol * scale))
                << "mu " << mu << " sample " << k;
          }
        EXPECT_GE(count[0], 1000);
        EXPECT_GE(count[1], 1000);
      }
  }
} // namespace
