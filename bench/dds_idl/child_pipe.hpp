#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace semap::bench {

// A child process (`sh -c "exec CMD"`) whose stdout the bench reads line by line.
struct Pipe {
  std::FILE* f = nullptr;
  explicit Pipe(const std::string& cmd) : f(popen(("exec " + cmd).c_str(), "r")) {
    if (!f) throw std::runtime_error("popen " + cmd);
  }
  ~Pipe() {
    if (f) pclose(f);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
  bool line(std::string& out) {
    char buf[1024];
    if (!std::fgets(buf, sizeof buf, f)) return false;
    out = buf;
    return true;
  }
  // Reads lines until one starts with `prefix`; throws when the child ends first.
  std::string expect(const std::string& prefix) {
    std::string l;
    while (line(l)) {
      if (l.rfind(prefix, 0) == 0) return l;
    }
    throw std::runtime_error("child ended before '" + prefix + "'");
  }
};

}  // namespace semap::bench
