#include "core/log.hpp"

#include <cstdio>
#include <mutex>
#include <utility>

namespace diefill::log {

namespace {
Level g_level = Level::normal;
std::mutex g_mutex;
std::vector<std::string> g_warnings;
}  // namespace

void set_level(Level level) { g_level = level; }
Level level() { return g_level; }

void write_info(std::string_view message) {
  if (g_level == Level::quiet) return;
  std::lock_guard lock(g_mutex);
  std::fprintf(stderr, "%.*s\n", int(message.size()), message.data());
}

void write_warning(std::string_view message, bool even_when_quiet) {
  std::lock_guard lock(g_mutex);
  g_warnings.emplace_back(message);
  if (g_level != Level::quiet || even_when_quiet) std::fprintf(stderr, "warning: %.*s\n", int(message.size()), message.data());
}

void write_debug(std::string_view message) {
  std::lock_guard lock(g_mutex);
  std::fprintf(stderr, "debug: %.*s\n", int(message.size()), message.data());
}

std::vector<std::string> take_warnings() {
  std::lock_guard lock(g_mutex);
  return std::exchange(g_warnings, {});
}

}  // namespace diefill::log
