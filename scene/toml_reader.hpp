#pragma once
// Strict reading of TOML scenes: every key is looked up through a Table, which knows the file
// and the line of each value, checks types, and reports keys nobody asked for as errors
// (typos fail early, with file and line). toml++ stays inside toml_reader.cpp.
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "dem/types.hpp"

namespace scene {

class TomlDocument;

class Table {
 public:
  // Values; absent keys give the default (or nullopt). Wrong types throw InputError.
  std::optional<double> number(const std::string& key);
  double number(const std::string& key, double fallback);
  std::optional<std::int64_t> integer(const std::string& key);
  std::optional<bool> boolean(const std::string& key);
  std::optional<std::string> string(const std::string& key);
  std::optional<dem::Vec3> vec3(const std::string& key);
  std::optional<std::vector<std::string>> strings(const std::string& key);
  bool has(const std::string& key) const;
  // A number or a string (time_step = "auto").
  std::optional<double> number_or(const std::string& key, const std::string& word, bool& is_word);
  // A length [m]: a number of metres or a string with its unit, "0.2 mm" (core/length.hpp); with
  // `word`, that word too (skin = "auto").
  std::optional<double> length(const std::string& key);
  std::optional<double> length_or(const std::string& key, const std::string& word, bool& is_word);

  std::optional<Table> table(const std::string& key);
  std::vector<Table> tables(const std::string& key);  // array of tables

  // Throws InputError for every key of this table that was never looked up.
  void finish() const;
  // An InputError naming this table's key (with file and line).
  [[noreturn]] void fail(const std::string& key, const std::string& problem, const std::string& remedy) const;
  const std::string& path() const { return path_; }

 private:
  friend class TomlDocument;
  Table(const void* node, std::string path, std::shared_ptr<const std::string> file)
      : node_(node), path_(std::move(path)), file_(std::move(file)) {}
  const void* find(const std::string& key);
  std::string where(const std::string& key) const;
  const void* node_;  // toml::table
  std::string path_;
  std::shared_ptr<const std::string> file_;
  mutable std::shared_ptr<std::set<std::string>> used_ = std::make_shared<std::set<std::string>>();
};

class TomlDocument {
 public:
  // Parses `path` (or `text` when given, reported as `path`); throws InputError with the line.
  static TomlDocument parse(const std::filesystem::path& path, std::optional<std::string> text = std::nullopt);
  // Applies `key.path=value` overrides (value in TOML syntax; bare words become strings).
  void apply_overrides(const std::vector<std::string>& overrides);
  Table root();

  TomlDocument(TomlDocument&&) noexcept;
  ~TomlDocument();

 private:
  TomlDocument();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scene
