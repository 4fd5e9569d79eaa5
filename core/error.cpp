#include "core/error.hpp"

namespace diefill {

namespace {
std::string compose(const std::string& file, const std::string& field, const std::string& problem,
                    const std::string& remedy) {
  std::string msg;
  if (!file.empty()) msg += file + ": ";
  if (!field.empty()) msg += field + ": ";
  msg += problem;
  if (!remedy.empty()) msg += ". " + remedy;
  return msg;
}
}  // namespace

InputError::InputError(std::string file, std::string field, const std::string& problem,
                       std::string remedy)
    : std::runtime_error(compose(file, field, problem, remedy)),
      file_(std::move(file)),
      field_(std::move(field)),
      remedy_(std::move(remedy)) {}

}  // namespace diefill
