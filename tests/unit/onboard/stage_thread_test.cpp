#include "semap/onboard/stage_thread.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace semap::onboard {
namespace {

struct Figures {
  int cpus_allowed = -1;  // CPUs in the thread's affinity mask, as the thread saw it
  int cpu = -1;           // the CPU it ran on
};

// The thread's affinity as the thread itself sees it, shared through the stage's figures.
Figures run_stage(std::vector<int> cpus) {
  StageThread<Figures> stage;
  std::atomic<bool> done{false};
  stage.start(
      [&](std::stop_token) {
        cpu_set_t set;
        CPU_ZERO(&set);
        ::pthread_getaffinity_np(::pthread_self(), sizeof(set), &set);
        stage.figures().cpus_allowed = CPU_COUNT(&set);
        stage.figures().cpu = ::sched_getcpu();
        stage.share();
        done = true;
      },
      "test", std::move(cpus));
  while (!done) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  stage.stop();
  return stage.stats();
}

TEST(StageThread, RunsOnTheCpusItIsPinnedTo) {
  cpu_set_t mine;
  CPU_ZERO(&mine);
  ASSERT_EQ(::sched_getaffinity(0, sizeof(mine), &mine), 0);
  int last = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &mine)) last = cpu;
  }
  ASSERT_GE(last, 0);
  const Figures pinned = run_stage({last});
  EXPECT_EQ(pinned.cpus_allowed, 1);
  EXPECT_EQ(pinned.cpu, last);
  // Unpinned, it keeps the process's affinity; a CPU the machine lacks leaves it there too.
  EXPECT_EQ(run_stage({}).cpus_allowed, CPU_COUNT(&mine));
  EXPECT_EQ(run_stage({1023}).cpus_allowed, CPU_COUNT(&mine));
}

}  // namespace
}  // namespace semap::onboard
