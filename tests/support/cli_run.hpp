#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace semap::test_support {

// What a command-line tool printed (stdout and stderr together) and its exit status (-1 when
// it did not exit normally).
struct CliResult {
  int status = -1;
  std::string out;
};

// Runs `exe args` through the shell and collects its output.
inline CliResult run_cli(const std::string& exe, const std::string& args) {
  const std::string command = exe + " " + args + " 2>&1";
  CliResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) r.out.append(buffer, n);
  const int status = pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace semap::test_support
