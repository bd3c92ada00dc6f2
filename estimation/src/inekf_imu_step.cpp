#include "semap/estimation/inekf_imu_step.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// The gyro-bias couplings need J1 = int_0^dt [u(s)]x e^{W s} ds with u(s) = s Gamma1(w s) a and
// J2 = int_0^dt [s^2 Gamma2(w s) a + (dt - s) u(s)]x e^{W s} ds. Expanding both exponentials in
// W_hat = [w dt]x gives J1 = dt^2 sum_kj alpha_kj [W_hat^k a]x W_hat^j and J2 = dt^3 sum_kj
// beta_kj [W_hat^k a]x W_hat^j, entire series whose terms of total order n = k + j shrink
// like (2 |w| dt)^n / (n + 2)!. Since W_hat^3 = t W_hat with t = -|w dt|^2, every W_hat^k a is
// a power of t times a, W_hat a or W_hat^2 a, and every W_hat^j a power of t times I, W_hat or
// W_hat^2, so each series collapses to 3x3 scalar polynomials in t:
//   J = [x0]x + [x1]x W_hat + [x2]x W_hat^2,  x_tau = sum_kappa S_kappa,tau(t) b_kappa,
// with b = (a, W_hat a, W_hat^2 a). Only a few powers of t are needed at IMU rates.
constexpr int kMaxPower = 20;               // of t: reaches total order 40 (|w dt| ~ 4 rad)
constexpr double kSeriesTolerance = 1e-13;  // relative to the leading term

int basis_of(int k) { return k == 0 ? 0 : (k % 2 == 1 ? 1 : 2); }
int t_power_of(int k) { return k == 0 ? 0 : (k - 1) / 2; }

// Coefficient of t^m of S1 (entries 0..8) and S2 (9..17), entry 3 kappa + tau, so that all
// 18 polynomials are evaluated together as one vector.
using SeriesCoefficients = Eigen::Matrix<double, 18, 1>;
using CollapsedSeries = std::array<SeriesCoefficients, kMaxPower + 1>;

CollapsedSeries make_collapsed_series() {
  constexpr int kMaxIndex = 2 * kMaxPower + 2;
  std::array<double, kMaxIndex + 4> factorial{};
  factorial[0] = 1.0;
  for (std::size_t i = 1; i < factorial.size(); ++i) factorial[i] = factorial[i - 1] * i;
  CollapsedSeries s;
  for (auto& c : s) c.setZero();
  for (int k = 0; k <= kMaxIndex; ++k) {
    for (int j = 0; j <= kMaxIndex; ++j) {
      const int m = t_power_of(k) + t_power_of(j);
      if (m > kMaxPower) continue;
      const double n = k + j;
      const double alpha = 1.0 / ((n + 2.0) * factorial[k + 1] * factorial[j]);
      const double beta = (1.0 / factorial[k + 2] + 1.0 / (factorial[k + 1] * (n + 2.0))) /
                          (factorial[j] * (n + 3.0));
      s[m](3 * basis_of(k) + basis_of(j)) += alpha;
      s[m](9 + 3 * basis_of(k) + basis_of(j)) += beta;
    }
  }
  return s;
}

const CollapsedSeries kSeries = make_collapsed_series();

// Largest |w dt| for which powers of t up to M suffice, i.e. the first omitted terms (total
// order 2M + 1, size ~ (2 theta)^(2M+1) / (2M + 3)! relative to the leading one) are below
// the tolerance; found once by bisection so the per-step choice is a few comparisons.
std::array<double, kMaxPower + 1> make_series_limits() {
  const auto omitted = [](double theta, int n) {
    double e = theta * 4.0 / 6.0;
    for (int i = 1; i <= n; ++i) e *= 2.0 * theta / (i + 3.0);
    return e;
  };
  std::array<double, kMaxPower + 1> limits{};
  for (int m = 0; m <= kMaxPower; ++m) {
    double lo = 0.0;
    double hi = 8.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (omitted(mid, 2 * m) <= kSeriesTolerance ? lo : hi) = mid;
    }
    limits[m] = lo;
  }
  return limits;
}

const std::array<double, kMaxPower + 1> kSeriesLimits = make_series_limits();

int series_power(double theta) {
  int m = 0;
  while (m < kMaxPower && theta > kSeriesLimits[m]) ++m;
  return m;
}

// [x0]x + [x1]x [phi]x + [x2]x [phi]x^2 = [x0 - (x2.phi) phi]x + phi (x1 + x2 x phi)^T - (x1.phi)
// I, from [x]x [phi]x = phi x^T - (x.phi) I and [x]x [phi]x^2 = phi (x cross phi)^T - (x.phi)
// [phi]x.
inline Matrix3d collapsed_matrix(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                                 const Vector3d& phi) {
  const Vector3d m = x0 - x2.dot(phi) * phi;
  const Vector3d n = x1 + x2.cross(phi);
  const double d = x1.dot(phi);
  Matrix3d c;
  c << -d, -m.z(), m.y(), m.z(), -d, -m.x(), -m.y(), m.x(), -d;
  c.noalias() += phi * n.transpose();
  return c;
}

}  // namespace

Matrix9 se23_adjoint(const Matrix3d& r, const Vector3d& v, const Vector3d& p) {
  Matrix9 ad = Matrix9::Zero();
  ad.block<3, 3>(kRot, kRot) = r;
  ad.block<3, 3>(kVel, kVel) = r;
  ad.block<3, 3>(kPos, kPos) = r;
  ad.block<3, 3>(kVel, kRot) = skew(v) * r;
  ad.block<3, 3>(kPos, kRot) = skew(p) * r;
  return ad;
}

Matrix15 world_from_left(const NavState& s) {
  Matrix15 t = Matrix15::Identity();
  t.topLeftCorner<9, 9>() = se23_adjoint(s.rotation, s.velocity, s.position);
  return t;
}

Matrix15 left_from_world(const NavState& s) {
  // Ad_X^-1 = Ad_{X^-1} with X^-1 = (R^T, -R^T v, -R^T p).
  const Matrix3d rt = s.rotation.transpose();
  Matrix15 t = Matrix15::Identity();
  t.topLeftCorner<9, 9>() = se23_adjoint(rt, -rt * s.velocity, -rt * s.position);
  return t;
}

Matrix9 gravity_shear(const Vector3d& gravity, double t) {
  Matrix9 f = Matrix9::Identity();
  const Matrix3d gx = skew(gravity);
  f.block<3, 3>(kVel, kRot) = gx * t;
  f.block<3, 3>(kPos, kRot) = gx * (0.5 * t * t);
  f.block<3, 3>(kPos, kVel) = Matrix3d::Identity() * t;
  return f;
}

InekfImuStep InekfImuStep::compute(const Matrix3d& r, const Vector3d& v, const Vector3d& p,
                                   const Vector3d& w, const Vector3d& a, double dt,
                                   const Vector3d& gravity, double t0) {
  InekfImuStep step;
  step.dt = dt;
  step.t0 = t0;
  const double t1 = t0 + dt;
  step.c = v - t0 * gravity;
  step.e = p - t0 * v + (0.5 * t0 * t0) * gravity;
  const Vector3d phi = w * dt;
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  const auto co = gamma_coefficients(theta);
  // R Gamma_k = g0 R + g1 R K + g2 R K^2 with K = [phi]x, R K = [R phi]x R and
  // R K^2 = (R phi) phi^T - |phi|^2 R: three rotation integrals for the price of one product.
  const Vector3d psi = r * phi;
  Matrix3d rk;
  for (int j = 0; j < 3; ++j) rk.col(j) = psi.cross(r.col(j));
  Matrix3d rk2 = psi * phi.transpose();
  rk2 -= theta2 * r;
  step.rotation = r + co.a0 * rk + co.b0 * rk2;
  const Matrix3d a1 = dt * (r + co.a1 * rk + co.b1 * rk2);               // R Gamma1 dt
  const Matrix3d a2 = (dt * dt) * (0.5 * r + co.a2 * rk + co.b2 * rk2);  // R Gamma2 dt^2
  step.dv.noalias() = a1 * a;
  step.dp.noalias() = a2 * a;

  // G = int_0^dt F(dt - s) Ad_X(s) B ds with B = -[I 0; 0 I; 0 0]; referred to the window
  // start, F(-t1) G = -int F(-t0 - s) Ad_X(s) ds B. In world form (as for the filter without
  // windows, t0 = 0) the blocks are G_Rg = G_va = -A1, G_pa = -A2 with A1 = R Gamma1 dt,
  // A2 = R Gamma2 dt^2, G_vg = -[v + g dt]x A1 - R J1, G_pg = -[p + v dt + g dt^2/2]x A1 - R J2;
  // the shear F(-t1) turns v + g dt into c, p + v dt + g dt^2/2 into e, adds t1 R J1 to the
  // position row and t1 A1 to G_pa. With c_b = R^T c, e_b = R^T e ([x]x R = R [R^T x]x):
  //   vel: -R ([c_b]x Gamma1 dt + J1),  pos: -R ([e_b]x Gamma1 dt + J2 - t1 J1),
  // where [x]x Gamma1 dt is the collapsed matrix of dt (1, a1, b1)_tau x, so each row block is
  // one collapsed matrix and one rotation.
  const double t = -theta2;
  const int degree = series_power(theta);
  SeriesCoefficients s = kSeries[degree];
  for (int m = degree - 1; m >= 0; --m) s = s * t + kSeries[m];
  Matrix3d basis;  // columns a, W_hat a, W_hat^2 a
  basis.col(0) = a;
  basis.col(1) = phi.cross(a);
  basis.col(2) = phi.cross(basis.col(1));
  // x_tau = sum_kappa S(kappa, tau) b_kappa, i.e. X = basis S with S stored row-major; J1 and
  // J2 - t1 J1 are the collapsed matrices of basis (dt^2 S1) and basis (dt^3 S2 - t1 dt^2 S1).
  // Everything is negated here, so that the products below give -R (...) directly.
  const double dt2 = dt * dt;
  const Eigen::Matrix<double, 9, 1> sv = (-dt2) * s.head<9>();
  const Eigen::Matrix<double, 9, 1> sp = (-dt2 * dt) * s.tail<9>() - t1 * sv;
  using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const Eigen::RowVector3d gamma1_terms(-dt, -dt * co.a1, -dt * co.b1);
  Eigen::Matrix<double, 3, 6> z;
  z.leftCols<3>().noalias() = basis * Eigen::Map<const RowMajor3>(sv.data());
  z.rightCols<3>().noalias() = basis * Eigen::Map<const RowMajor3>(sp.data());
  z.leftCols<3>().noalias() += (r.transpose() * step.c) * gamma1_terms;
  z.rightCols<3>().noalias() += (r.transpose() * step.e) * gamma1_terms;
  Eigen::Matrix<double, 3, 6> body;
  body.leftCols<3>() = collapsed_matrix(z.col(0), z.col(1), z.col(2), phi);
  body.rightCols<3>() = collapsed_matrix(z.col(3), z.col(4), z.col(5), phi);
  Eigen::Matrix<double, 3, 6> world;
  world.noalias() = r * body;
  auto& g = step.coupling;
  g.bottomRows<kPaddedRows - 9>().setZero();
  g.block<3, 3>(kRot, 0) = -a1;
  g.block<3, 3>(kVel, 0) = world.leftCols<3>();
  g.block<3, 3>(kPos, 0) = world.rightCols<3>();
  g.block<3, 3>(kRot, 3).setZero();
  g.block<3, 3>(kVel, 3) = -a1;
  g.block<3, 3>(kPos, 3) = t1 * a1 - a2;
  return step;
}

Matrix15 InekfImuStep::dense(const Vector3d& gravity) const {
  Matrix15 f = Matrix15::Identity();
  f.topLeftCorner<9, 9>() = gravity_shear(gravity, dt);
  f.topRightCorner<9, 6>() = gravity_shear(gravity, t0 + dt) * coupling.topRows<9>();
  return f;
}

}  // namespace semap::estimation
