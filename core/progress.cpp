#include "core/progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

#include "core/log.hpp"

namespace diefill {

Progress::Progress(std::string what, double total)
    : what_(std::move(what)), total_(total), terminal_(::isatty(STDERR_FILENO) == 1) {}

void Progress::update(double done, const std::string& detail) {
  if (log::level() == log::Level::quiet) return;
  const double now = clock_.seconds();
  const double interval = terminal_ ? 0.25 : 5.0;
  if (last_print_ >= 0 && now - last_print_ < interval) return;
  last_print_ = now;
  const double fraction = total_ > 0 ? std::min(1.0, done / total_) : 0.0;
  const double left = fraction > 0 ? now * (1 - fraction) / fraction : 0.0;
  const std::string line = fmt::format("{}: {:.1f} %, {}, {:.0f} s elapsed, about {:.0f} s left", what_,
                                       100 * fraction, detail, now, left);
  if (terminal_) std::fprintf(stderr, "\r%s\033[K", line.c_str());
  else log::write_info(line);
}

void Progress::finish(const std::string& detail) {
  if (log::level() == log::Level::quiet) return;
  if (terminal_) std::fprintf(stderr, "\r\033[K");
  log::write_info(fmt::format("{}: done in {:.1f} s, {}", what_, clock_.seconds(), detail));
}

}  // namespace diefill
