#include "semap/estimation/so3.hpp"

#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace semap::estimation {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Gamma_m(phi) = sum_n [phi]^n / (n + m)!, read off the exponential of a nilpotent-augmented
// matrix: exp([[K, I, 0], [0, 0, I], [0, 0, 0]]) has Gamma_1 and Gamma_2 in its first row.
struct NumericGammas {
  Matrix3d g0, g1, g2;
};
NumericGammas numeric(const Vector3d& phi) {
  Eigen::Matrix<double, 9, 9> m = Eigen::Matrix<double, 9, 9>::Zero();
  m.block<3, 3>(0, 0) = skew(phi);
  m.block<3, 3>(0, 3).setIdentity();
  m.block<3, 3>(3, 6).setIdentity();
  const Eigen::Matrix<double, 9, 9> e = m.exp();
  return {e.block<3, 3>(0, 0), e.block<3, 3>(0, 3), e.block<3, 3>(0, 6)};
}

std::vector<Vector3d> test_angles() {
  const Vector3d axis = Vector3d(0.3, -0.5, 0.8).normalized();
  std::vector<Vector3d> out;
  for (double theta :
       {0.0, 1e-12, 1e-8, 1e-5, 1e-3, 0.0999999, 0.1, 0.1000001, 0.5, 1.5, 3.0, 3.14159}) {
    out.push_back(axis * theta);
  }
  return out;
}

TEST(So3, GammaFunctionsMatchNumericalExponential) {
  for (const Vector3d& phi : test_angles()) {
    const NumericGammas n = numeric(phi);
    EXPECT_TRUE(gamma0(phi).allFinite());
    EXPECT_LT((gamma0(phi) - n.g0).norm(), 1e-13) << phi.norm();
    EXPECT_LT((gamma1(phi) - n.g1).norm(), 1e-13) << phi.norm();
    EXPECT_LT((gamma2(phi) - n.g2).norm(), 1e-13) << phi.norm();
  }
}

TEST(So3, SeriesBranchIsContinuousAtSwitchPoint) {
  // Coefficients enter the matrices multiplied by theta and theta^2.
  const double t = 0.1;
  const auto below = gamma_coefficients(t - 1e-12);
  const auto above = gamma_coefficients(t + 1e-12);
  EXPECT_NEAR(below.a0 * t, above.a0 * t, 1e-14);
  EXPECT_NEAR(below.b0 * t * t, above.b0 * t * t, 1e-14);
  EXPECT_NEAR(below.b1 * t * t, above.b1 * t * t, 1e-14);
  EXPECT_NEAR(below.b2 * t * t, above.b2 * t * t, 1e-14);
}

TEST(So3, LogInvertsExpAndJacobianInverse) {
  for (const Vector3d& phi : test_angles()) {
    EXPECT_LT((so3_log(gamma0(phi)) - phi).norm(), 1e-9) << phi.norm();
    if (phi.norm() < 3.0) {
      EXPECT_LT((gamma1_inverse(phi) * gamma1(phi) - Matrix3d::Identity()).norm(), 1e-12);
    }
  }
}

TEST(So3, YawAndWrap) {
  EXPECT_NEAR(yaw_of(rotation_from_rpy(0.1, -0.2, 1.3)), 1.3, 1e-12);
  EXPECT_NEAR(wrap_angle(3.0 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrap_angle(-0.5 - 2.0 * M_PI), -0.5, 1e-12);
}

}  // namespace
}  // namespace semap::estimation
