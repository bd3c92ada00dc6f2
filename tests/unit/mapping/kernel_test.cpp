#include "semap/mapping/kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace semap::mapping {
namespace {

TEST(SparseKernel, MatchesTheClosedFormAndVanishesAtEll) {
  const SparseKernel k(10.0f, 0.3f);
  EXPECT_DOUBLE_EQ(k(0.0), 10.0);
  EXPECT_NEAR(k(0.3), 0.0, 1e-12);
  EXPECT_EQ(k(0.31), 0.0);
  // The kernel keeps sf2 and ell as floats.
  const double d = 0.12, r = d / static_cast<double>(0.3f), a = 2 * std::numbers::pi * r;
  const double expected =
      10.0 * ((2 + std::cos(a)) * (1 - r) / 3 + std::sin(a) / (2 * std::numbers::pi));
  EXPECT_DOUBLE_EQ(k(d), expected);
  // Monotone decreasing over the support.
  for (double x = 0.0; x < 0.3; x += 0.01) EXPECT_GE(k(x), k(x + 0.01));
}

TEST(KernelPolynomial, AgreesWithTheExactKernelAndVanishesAtEll) {
  for (const float ell : {0.3f, 0.5f, 1.7f}) {
    const SparseKernel exact(10.0f, ell);
    const KernelPolynomial poly(exact);
    double worst = 0.0;
    for (int i = 0; i <= 100000; ++i) {
      const double d = 1.05 * ell * i / 100000.0;
      const float value = poly(static_cast<float>(d * d));
      worst = std::max(worst, std::abs(value - exact(d)));
      // Positive inside the support (observed cells get evidence), 0 beyond.
      if (d < 0.999 * ell) {
        ASSERT_GT(value, 0.0f) << "d = " << d;
      } else {
        ASSERT_GE(value, 0.0f) << "d = " << d;
      }
    }
    EXPECT_LT(worst, 1e-6 * 10.0) << "ell = " << ell;
    EXPECT_EQ(poly(ell * ell), 0.0f);
    EXPECT_EQ(poly(1e9f), 0.0f);
    EXPECT_NEAR(poly(0.0f), 10.0f, 1e-6 * 10.0);
  }
}

TEST(SparseKernel, RejectsNonPositiveParameters) {
  EXPECT_THROW(SparseKernel(0.0f, 0.3f), std::invalid_argument);
  EXPECT_THROW(SparseKernel(1.0f, -1.0f), std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping
