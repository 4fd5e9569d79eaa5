#pragma once
// Progress of long work: on a terminal one live line, rewritten in place; off a terminal a log
// line every few seconds. Reports simulated time, percent, rate and the time left.
#include <string>

#include "core/timer.hpp"

namespace diefill {

class Progress {
 public:
  Progress(std::string what, double total);
  // `done` of `total` (for instance simulated seconds); `detail` is appended to the line.
  void update(double done, const std::string& detail);
  void finish(const std::string& detail);

 private:
  std::string what_;
  double total_;
  bool terminal_;
  Stopwatch clock_;
  double last_print_ = -1;
};

}  // namespace diefill
