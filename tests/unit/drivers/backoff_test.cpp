#include "semap/drivers/backoff.hpp"

#include <gtest/gtest.h>

namespace semap::drivers {
namespace {

using namespace std::chrono_literals;

TEST(Backoff, GrowsGeometricallyUpToTheCapAndResets) {
  Backoff b({.initial = 10ms, .max = 70ms, .factor = 2.0});
  EXPECT_EQ(b.next(), 10ms);
  EXPECT_EQ(b.next(), 20ms);
  EXPECT_EQ(b.next(), 40ms);
  EXPECT_EQ(b.next(), 70ms);
  EXPECT_EQ(b.next(), 70ms);
  EXPECT_EQ(b.attempts(), 5);
  b.reset();
  EXPECT_EQ(b.attempts(), 0);
  EXPECT_EQ(b.next(), 10ms);
}

TEST(Backoff, RejectsNonsense) {
  EXPECT_THROW(Backoff({.initial = 0ms, .max = 10ms, .factor = 2.0}), std::invalid_argument);
  EXPECT_THROW(Backoff({.initial = 20ms, .max = 10ms, .factor = 2.0}), std::invalid_argument);
  EXPECT_THROW(Backoff({.initial = 1ms, .max = 10ms, .factor = 0.5}), std::invalid_argument);
}

}  // namespace
}  // namespace semap::drivers
