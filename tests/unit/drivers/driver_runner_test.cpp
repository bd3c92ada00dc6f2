// DriverRunner's thread, reconnect and counting logic, exercised with a small driver that reads
// 32-bit values from a real file (removing the file stands for the device vanishing).
#include "semap/drivers/driver_runner.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>
#include <vector>

#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/realtime.hpp"

namespace semap::drivers {
namespace {

using namespace std::chrono_literals;

class FileDriver : public DriverRunner {
 public:
  FileDriver(std::string path, common::SpscRing<std::uint32_t>& ring, BackoffConfig backoff)
      : DriverRunner("file_driver", backoff), path_(std::move(path)), ring_(ring) {}
  ~FileDriver() override { stop(); }

 protected:
  void open_device() override {
    fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw_errno("open " + path_);
  }
  void service_device(std::stop_token) override {
    std::uint32_t value = 0;
    const ssize_t n = ::read(fd_, &value, sizeof(value));
    if (n == sizeof(value)) {
      counters().add_bytes(sizeof(value));
      deliver(ring_, std::move(value));
      return;
    }
    struct stat st {};
    if (::fstat(fd_, &st) == 0 && st.st_nlink == 0) {
      throw DriverError(path_ + ": removed", ENODEV);
    }
    std::this_thread::sleep_for(1ms);
  }
  void close_device() noexcept override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  std::string path_;
  common::SpscRing<std::uint32_t>& ring_;
  int fd_ = -1;
};

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return done();
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

class DriverRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = std::filesystem::temp_directory_path() /
            ("semap-driver-runner-" + std::to_string(::getpid()) + "-" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove(path_);
  }
  void TearDown() override { std::filesystem::remove(path_); }

  void write_values(std::uint32_t first, std::uint32_t count) {
    std::ofstream out(path_, std::ios::binary | std::ios::app);
    for (std::uint32_t v = first; v < first + count; ++v) {
      out.write(reinterpret_cast<const char*>(&v), sizeof(v));
    }
  }

  std::filesystem::path path_;
};

TEST_F(DriverRunnerTest, NeverBlocksOnAFullRingAndCountsTheDrops) {
  write_values(0, 100);
  common::SpscRing<std::uint32_t> ring(8, common::OverflowPolicy::kDropOldest);
  FileDriver driver(path_.string(), ring, {});
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.stats().frames == 100; }, 5s));
  driver.stop();
  EXPECT_EQ(driver.stats().ring_drops, 92u);
  EXPECT_EQ(driver.stats().bytes, 400u);
  std::uint32_t v = 0;
  ASSERT_TRUE(ring.try_pop(v));
  EXPECT_EQ(v, 92u);  // drop-oldest kept the newest eight
}

TEST_F(DriverRunnerTest, RetriesAMissingDeviceWithoutCountingAReconnect) {
  common::SpscRing<std::uint32_t> ring(64, common::OverflowPolicy::kDropOldest);
  FileDriver driver(path_.string(), ring, {.initial = 5ms, .max = 20ms, .factor = 2.0});
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.failures() >= 2; }, 5s));
  EXPECT_EQ(driver.state(), DriverState::kConnecting);
  EXPECT_NE(driver.last_error().find("No such file"), std::string::npos);
  EXPECT_TRUE(driver.last_loss().empty());  // never connected, so nothing was lost
  write_values(7, 1);
  ASSERT_TRUE(wait_until([&] { return driver.stats().frames == 1; }, 5s));
  EXPECT_EQ(driver.state(), DriverState::kRunning);
  EXPECT_EQ(driver.stats().reconnects, 0u);
}

TEST_F(DriverRunnerTest, ReportsALostDeviceAndCountsTheReconnect) {
  write_values(0, 3);
  common::SpscRing<std::uint32_t> ring(64, common::OverflowPolicy::kDropOldest);
  FileDriver driver(path_.string(), ring, {.initial = 5ms, .max = 20ms, .factor = 2.0});
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.stats().frames == 3; }, 5s));
  std::filesystem::remove(path_);
  ASSERT_TRUE(wait_until([&] { return driver.failures() >= 1; }, 5s));
  EXPECT_NE(driver.state(), DriverState::kRunning);
  EXPECT_NE(driver.last_loss().find("removed"), std::string::npos) << driver.last_loss();
  write_values(3, 2);
  ASSERT_TRUE(wait_until([&] { return driver.stats().frames == 5; }, 5s));
  EXPECT_EQ(driver.stats().reconnects, 1u);
  driver.stop();
  EXPECT_EQ(driver.state(), DriverState::kStopped);
}

TEST_F(DriverRunnerTest, StopIsPromptDuringALongBackoff) {
  common::SpscRing<std::uint32_t> ring(8, common::OverflowPolicy::kDropOldest);
  FileDriver driver(path_.string(), ring, {.initial = 10'000ms, .max = 10'000ms, .factor = 1.0});
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.failures() == 1; }, 5s));
  const auto t0 = std::chrono::steady_clock::now();
  driver.stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
  EXPECT_EQ(driver.state(), DriverState::kStopped);
}

// Records the scheduling its thread runs with.
class SchedulingDriver : public DriverRunner {
 public:
  explicit SchedulingDriver(int realtime_priority, std::vector<int> cpus = {})
      : DriverRunner("scheduling_driver", {}, realtime_priority, std::move(cpus)) {}
  ~SchedulingDriver() override { stop(); }

  std::atomic<int> policy{-1};
  std::atomic<int> priority{-1};
  std::atomic<int> cpu_count{-1};
  std::atomic<bool> on_cpu0{false};

 protected:
  void open_device() override {}
  void service_device(std::stop_token) override {
    int p = 0;
    sched_param param{};
    ::pthread_getschedparam(::pthread_self(), &p, &param);
    priority.store(param.sched_priority);
    cpu_set_t set;
    CPU_ZERO(&set);
    ::pthread_getaffinity_np(::pthread_self(), sizeof(set), &set);
    on_cpu0.store(CPU_ISSET(0, &set));
    cpu_count.store(CPU_COUNT(&set));
    // Data the "kernel" stamped 3 ms ago: the lateness the driver reports.
    record_wakeup(common::Stamp::now() + (-0.003));
    policy.store(p);
    std::this_thread::sleep_for(1ms);
  }
  void close_device() noexcept override {}
};

TEST(DriverRealtime, ThreadRunsAtTheRequestedFifoPriorityOrSaysWhyNot) {
  SchedulingDriver driver(7);
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.policy.load() >= 0; }, 5s));
  if (driver.realtime_priority() == 7) {
    EXPECT_EQ(driver.policy.load(), SCHED_FIFO);
    EXPECT_EQ(driver.priority.load(), 7);
    EXPECT_EQ(driver.last_error(), "");
  } else {
    // Without CAP_SYS_NICE or an RLIMIT_RTPRIO of 7 the kernel refuses; the driver runs on.
    EXPECT_EQ(driver.realtime_priority(), 0);
    EXPECT_EQ(driver.policy.load(), SCHED_OTHER);
    EXPECT_NE(driver.last_error().find("SCHED_FIFO priority 7 refused"), std::string::npos)
        << driver.last_error();
    EXPECT_EQ(driver.state(), DriverState::kRunning);
  }
}

TEST(DriverRealtime, NormalSchedulingUnlessAsked) {
  SchedulingDriver driver(0);
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.policy.load() >= 0; }, 5s));
  EXPECT_EQ(driver.policy.load(), SCHED_OTHER);
  EXPECT_EQ(driver.realtime_priority(), 0);
}

TEST(DriverRealtime, ThreadRunsOnTheCpusItIsPinnedTo) {
  SchedulingDriver pinned(0, {0});
  pinned.start();
  ASSERT_TRUE(wait_until([&] { return pinned.policy.load() >= 0; }, 5s));
  EXPECT_EQ(pinned.cpu_count.load(), 1);
  EXPECT_TRUE(pinned.on_cpu0.load());
  EXPECT_EQ(pinned.last_error(), "");
  // A CPU the machine does not have: reported, and the thread runs on where it was.
  SchedulingDriver missing(0, {1023});
  missing.start();
  ASSERT_TRUE(wait_until([&] { return missing.policy.load() >= 0; }, 5s));
  EXPECT_NE(missing.last_error().find("CPU affinity {1023} refused"), std::string::npos)
      << missing.last_error();
  EXPECT_EQ(missing.state(), DriverState::kRunning);
  EXPECT_EQ(set_cpu_affinity(std::vector<int>{-1}), "CPU -1 is outside the CPU set");
}

TEST(DriverRealtime, ReportsTheWakeUpLatenessOfItsThread) {
  SchedulingDriver driver(0);
  driver.start();
  ASSERT_TRUE(wait_until([&] { return driver.stats().wakeup.count >= 10; }, 5s));
  const auto wakeup = driver.stats().wakeup;
  EXPECT_GE(wakeup.p50_ms, 3.0f);
  EXPECT_LT(wakeup.p50_ms, 1000.0f);
  EXPECT_GE(wakeup.max_ms, wakeup.p99_ms);
}

TEST(DriverRealtime, LocksMemoryOrSaysWhyNot) {
  const std::string refused = lock_memory();
  std::ifstream status("/proc/self/status");
  std::string line, locked;
  while (std::getline(status, line)) {
    if (line.rfind("VmLck:", 0) == 0) locked = line;
  }
  if (refused.empty()) {
    EXPECT_NE(locked, "VmLck:\t       0 kB") << "mlockall succeeded but nothing is locked";
    ::munlockall();
  } else {
    EXPECT_NE(refused.find("mlockall refused"), std::string::npos) << refused;
    EXPECT_EQ(locked, "VmLck:\t       0 kB") << "refused, yet memory is locked: " << refused;
  }
}

// The longest silence between two messages is what an operator looks for after a device went
// away or a bus went off: it grows only with a longer silence.
TEST(DriverCountersGap, KeepsTheLongestTimeBetweenTwoMessages) {
  DriverCounters counters;
  counters.add_frame();
  EXPECT_EQ(counters.snapshot().longest_gap_s, 0.0) << "one message has no gap";
  std::this_thread::sleep_for(200ms);
  counters.add_frame();
  const double gap = counters.snapshot().longest_gap_s;
  EXPECT_GE(gap, 0.19);
  EXPECT_LT(gap, 5.0);
  std::this_thread::sleep_for(20ms);
  counters.add_frame();
  EXPECT_EQ(counters.snapshot().longest_gap_s, gap) << "a shorter gap changes nothing";
}

TEST(DriverRealtime, RefusalsNameThePriorityAndTheReason) {
  EXPECT_EQ(set_realtime_priority(100), "SCHED_FIFO priority 100 refused: Invalid argument");
  EXPECT_THROW(SchedulingDriver(100), std::invalid_argument);
  EXPECT_THROW(SchedulingDriver(-1), std::invalid_argument);
}

}  // namespace
}  // namespace semap::drivers
