#pragma once

// What every dataset reader reports: input it could not use. A reader skips a frame whose line,
// pose or partner is bad and names it in an InputProblem; it throws DatasetError only when the
// dataset as a whole cannot be read (a required file or folder is missing or unusable).
#include <stdexcept>
#include <string>

namespace semap::perception::datasets {

// A dataset that cannot be read at all, or a file a caller asked for that cannot be used; the
// message names the file (and the line where there is one).
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One piece of input that was skipped: `where` is "file:line" for a line of a text file and
// "file" for a whole file (a scan, an image); `what` says why.
struct InputProblem {
  std::string where;
  std::string what;

  std::string text() const { return where + ": " + what; }
};

}  // namespace semap::perception::datasets
