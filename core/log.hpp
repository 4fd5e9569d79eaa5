#pragma once
// Minimal leveled logging to stderr. Warnings are also kept so that reports can list them; quiet
// (the ranks after the first of a split run, whose warnings are rank 0's) prints none.
#include <fmt/core.h>

#include <string>
#include <string_view>
#include <vector>

namespace diefill::log {

enum class Level { quiet, normal, verbose };
void set_level(Level level);
Level level();

void write_info(std::string_view message);
void write_warning(std::string_view message, bool even_when_quiet = false);
void write_debug(std::string_view message);
// Every warning written since the last call, oldest first; clears the list.
std::vector<std::string> take_warnings();

template <typename... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
  write_info(fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void warn(fmt::format_string<Args...> f, Args&&... args) {
  write_warning(fmt::format(f, std::forward<Args>(args)...));
}
// A warning about this process alone (a file it read), printed even where the level is quiet.
template <typename... Args>
void warn_here(fmt::format_string<Args...> f, Args&&... args) {
  write_warning(fmt::format(f, std::forward<Args>(args)...), true);
}
template <typename... Args>
void debug(fmt::format_string<Args...> f, Args&&... args) {
  if (level() == Level::verbose) write_debug(fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace diefill::log
