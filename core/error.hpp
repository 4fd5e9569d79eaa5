#pragma once
// Errors by phase (docs/INTERFACE.md, "Exit status"): configuration and input problems throw a typed exception that
// names the file, the field and what to do; the front end maps the type to an exit status.
#include <stdexcept>
#include <string>

namespace diefill {

// Bad input: exit status 2. `file` is the path the user gave (or empty), `field` the key,
// option or mesh property at fault, `remedy` what the user should do about it.
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string field, const std::string& problem, std::string remedy);
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  const std::string& remedy() const { return remedy_; }

 private:
  std::string file_, field_, remedy_;
};

// The simulation stopped on a stability check: exit status 3. It carries the time step it was
// stepping with, a property of the settings that a stopped run still has (the speed-accuracy
// study charts it for every setting, stopped or not).
class StabilityError : public std::runtime_error {
 public:
  StabilityError(const std::string& message, double time_step_s) : std::runtime_error(message), time_step_s_(time_step_s) {}
  double time_step_s() const { return time_step_s_; }

 private:
  double time_step_s_;
};

enum ExitStatus : int { exit_ok = 0, exit_other = 1, exit_bad_input = 2, exit_unstable = 3, exit_interrupted = 130 };

}  // namespace diefill
