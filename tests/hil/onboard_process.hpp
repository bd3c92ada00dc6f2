#pragma once
// semap-onboard and its tools as child processes of a HIL test, and the figures of the run
// summary the tests check (shared by onboard_hil_test.cpp and onboard_faults_hil_test.cpp).
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "hil_env.hpp"

namespace semap::hil {

using namespace std::chrono_literals;

inline std::filesystem::path write_file(const std::filesystem::path& path,
                                        const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// A child process with stdout and stderr in one file.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::filesystem::path& output)
      : output_(output) {
    const int fd = ::open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error("cannot create " + output.string());
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      ::execv(args[0], args.data());
      std::perror(args[0]);
      ::_exit(127);
    }
    ::close(fd);
    if (pid_ < 0) throw std::runtime_error("fork failed");
  }
  ~Child() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool running() { return pid_ > 0 && !poll(); }
  // The exit code (128 + signal when killed), or nothing while it still runs after `timeout`.
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    wait_until([&] { return poll().has_value(); }, timeout);
    return status_;
  }
  // SIGTERM, then SIGKILL if it does not exit within `grace`.
  int stop(std::chrono::milliseconds grace) {
    if (running()) ::kill(pid_, SIGTERM);
    if (auto code = wait(grace)) return *code;
    ::kill(pid_, SIGKILL);
    return wait(5s).value_or(-1);
  }
  std::string output() const { return read_file(output_); }

 private:
  const std::optional<int>& poll() {
    int status = 0;
    if (!status_ && ::waitpid(pid_, &status, WNOHANG) == pid_) {
      status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    return status_;
  }

  std::filesystem::path output_;
  pid_t pid_ = -1;
  std::optional<int> status_;
};

// The figures the test checks, from semap-onboard's summary.
struct Summary {
  bool initialised = false;
  unsigned long imu_samples = 0, gnss_fixes = 0;
  unsigned long camera_frames = 0, camera_bad = 0;
  unsigned long perception_frames = 0, clouds = 0, cloud_points = 0, perception_bad = 0;
  unsigned long scans = 0, blocks = 0;
  std::optional<double> pose_rmse;  // only on the simulated rig
  std::string missing;              // summary lines not found
};

inline Summary parse_summary(const std::string& out) {
  Summary s;
  std::smatch m;
  const auto find = [&](const char* name, const std::regex& re) {
    if (std::regex_search(out, m, re)) return true;
    s.missing += std::string(name) + " ";
    return false;
  };
  if (find("estimation",
           std::regex(R"(estimation +: (\d+) IMU samples, (\d+) GNSS fixes.*initialised=(\w+))"))) {
    s.imu_samples = std::stoul(m[1]);
    s.gnss_fixes = std::stoul(m[2]);
    s.initialised = m[3] == "yes";
  }
  if (find("camera driver", std::regex(R"(camera driver +: (\d+) frames, (\d+) bad)"))) {
    s.camera_frames = std::stoul(m[1]);
    s.camera_bad = std::stoul(m[2]);
  }
  if (find("perception", std::regex(R"(perception +: (\d+) frames, (\d+) clouds mapped \((\d+) )"
                                    R"(points\), \d+ passed over, \d+ unpaired, (\d+) bad)"))) {
    s.perception_frames = std::stoul(m[1]);
    s.clouds = std::stoul(m[2]);
    s.cloud_points = std::stoul(m[3]);
    s.perception_bad = std::stoul(m[4]);
  }
  if (find("mapping", std::regex(R"(mapping +: (\d+) scans, .*, (\d+) blocks,)"))) {
    s.scans = std::stoul(m[1]);
    s.blocks = std::stoul(m[2]);
  }
  if (std::regex_search(out, m, std::regex(R"(pose vs truth +: position RMSE ([0-9.]+) m)"))) {
    s.pose_rmse = std::stod(m[1]);
  }
  return s;
}

}  // namespace semap::hil
