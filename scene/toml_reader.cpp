#include "scene/toml_reader.hpp"

#include <fmt/core.h>

#include <sstream>
#include <toml++/toml.h>

#include "core/error.hpp"
#include "core/length.hpp"

namespace scene {

using diefill::InputError;

struct TomlDocument::Impl {
  toml::table table;
  std::shared_ptr<const std::string> file;
};

TomlDocument::TomlDocument() : impl_(std::make_unique<Impl>()) {}
TomlDocument::TomlDocument(TomlDocument&&) noexcept = default;
TomlDocument::~TomlDocument() = default;

TomlDocument TomlDocument::parse(const std::filesystem::path& path, std::optional<std::string> text) {
  TomlDocument doc;
  doc.impl_->file = std::make_shared<const std::string>(path.string());
  try {
    doc.impl_->table = text ? toml::parse(*text, path.string()) : toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    if (!text && !std::filesystem::exists(path))
      throw InputError(path.string(), "", "no such file", "Check the path");
    throw InputError(fmt::format("{}:{}", path.string(), e.source().begin.line), "",
                     fmt::format("not valid TOML: {}", e.description()), "Correct the syntax at that line");
  }
  return doc;
}

void TomlDocument::apply_overrides(const std::vector<std::string>& overrides) {
  for (const std::string& item : overrides) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set", item, "is not KEY=VALUE", "Write for example --set simulation.duration=0.5");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    toml::table parsed;
    try {
      parsed = toml::parse("v = " + value);
    } catch (const toml::parse_error&) {
      parsed = toml::parse("v = \"" + value + "\"");  // a bare word is a string
    }
    // Walk the dotted path, through tables and array indices, creating tables as needed.
    toml::node* node = &impl_->table;
    std::stringstream parts(key);
    std::string part;
    std::vector<std::string> names;
    while (std::getline(parts, part, '.')) names.push_back(part);
    for (std::size_t n = 0; n + 1 < names.size(); ++n) {
      if (auto* t = node->as_table()) {
        if (!t->contains(names[n])) t->insert(names[n], toml::table{});
        node = t->get(names[n]);
      } else if (auto* a = node->as_array()) {
        std::size_t index = 0;
        try {
          index = std::stoul(names[n]);
        } catch (...) {
          throw InputError("--set", key, "'" + names[n] + "' is not an array index", "Index arrays of tables by number");
        }
        if (index >= a->size()) throw InputError("--set", key, "the index is past the end of the array", "Check the index");
        node = a->get(index);
      } else {
        throw InputError("--set", key, "'" + names[n] + "' is not a table", "Check the key");
      }
    }
    auto* target = node->as_table();
    if (!target) throw InputError("--set", key, "does not name a value in a table", "Check the key");
    target->insert_or_assign(names.back(), *parsed.get("v"));
  }
}

Table TomlDocument::root() { return Table(&impl_->table, "", impl_->file); }


namespace {
const toml::table& as_table(const void* node) { return *static_cast<const toml::table*>(node); }
}  // namespace

std::string Table::where(const std::string& key) const {
  const toml::node* n = as_table(node_).get(key);
  const auto& src = n ? n->source() : as_table(node_).source();
  return src.begin.line > 0 ? fmt::format("{}:{}", *file_, src.begin.line) : *file_ + " (--set)";
}

void Table::fail(const std::string& key, const std::string& problem, const std::string& remedy) const {
  throw InputError(where(key), path_.empty() ? key : path_ + "." + key, problem, remedy);
}

const void* Table::find(const std::string& key) {
  used_->insert(key);
  return as_table(node_).get(key);
}

bool Table::has(const std::string& key) const { return as_table(node_).contains(key); }

std::optional<double> Table::number(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  if (auto v = n->value<double>()) {
    if (!std::isfinite(*v)) fail(key, "is not a finite number", "Give a finite number");
    return *v;
  }
  fail(key, "must be a number", "Write it as a number in SI units");
}

double Table::number(const std::string& key, double fallback) { return number(key).value_or(fallback); }

std::optional<double> Table::number_or(const std::string& key, const std::string& word, bool& is_word) {
  const auto* n = static_cast<const toml::node*>(find(key));
  is_word = false;
  if (!n) return std::nullopt;
  if (auto s = n->value<std::string>()) {
    if (*s == word) {
      is_word = true;
      return std::nullopt;
    }
    fail(key, "must be a number or \"" + word + "\"", "Give seconds or \"" + word + "\"");
  }
  return number(key);
}

std::optional<double> Table::length(const std::string& key) {
  bool never = false;
  return length_or(key, "", never);
}

std::optional<double> Table::length_or(const std::string& key, const std::string& word, bool& is_word) {
  const auto* n = static_cast<const toml::node*>(find(key));
  is_word = false;
  if (!n) return std::nullopt;
  if (auto s = n->value<std::string>()) {
    if (!word.empty() && *s == word) {
      is_word = true;
      return std::nullopt;
    }
    if (const std::optional<diefill::Length> l = diefill::parse_length(*s)) return l->metres();
    fail(key, fmt::format("must be a length: metres, or a number with its unit{}, not \"{}\"", word.empty() ? "" : " or \"" + word + "\"", *s),
         "Write for example 0.0002 or \"0.2 mm\" (units m, mm, um, in)");
  }
  return number(key);
}

std::optional<std::int64_t> Table::integer(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  if (auto v = n->value_exact<std::int64_t>()) return *v;
  fail(key, "must be an integer", "Write a whole number");
}

std::optional<bool> Table::boolean(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  if (auto v = n->value_exact<bool>()) return *v;
  fail(key, "must be true or false", "Write true or false");
}

std::optional<std::string> Table::string(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  if (auto v = n->value_exact<std::string>()) return *v;
  fail(key, "must be a string", "Quote it");
}

std::optional<dem::Vec3> Table::vec3(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  const auto* a = n->as_array();
  if (!a || a->size() != 3) fail(key, "must be an array of three numbers", "Write [x, y, z] in SI units");
  dem::Vec3 out;
  for (std::size_t k = 0; k < 3; ++k) {
    auto v = a->get(k)->value<double>();
    if (!v || !std::isfinite(*v)) fail(key, "must be an array of three numbers", "Write [x, y, z] in SI units");
    out[int(k)] = *v;
  }
  return out;
}

std::optional<std::vector<std::string>> Table::strings(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  const auto* a = n->as_array();
  if (!a) fail(key, "must be an array of strings", "Write [\"a\", \"b\"]");
  std::vector<std::string> out;
  for (const auto& item : *a) {
    auto v = item.value_exact<std::string>();
    if (!v) fail(key, "must be an array of strings", "Write [\"a\", \"b\"]");
    out.push_back(*v);
  }
  return out;
}

std::optional<Table> Table::table(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  if (!n) return std::nullopt;
  const auto* t = n->as_table();
  if (!t) fail(key, "must be a table", "Write it as [" + key + "] or { ... }");
  return Table(t, path_.empty() ? key : path_ + "." + key, file_);
}

std::vector<Table> Table::tables(const std::string& key) {
  const auto* n = static_cast<const toml::node*>(find(key));
  std::vector<Table> out;
  if (!n) return out;
  const auto* a = n->as_array();
  if (!a) fail(key, "must be an array of tables", "Write each entry as [[" + key + "]]");
  for (std::size_t k = 0; k < a->size(); ++k) {
    const auto* t = a->get(k)->as_table();
    if (!t) fail(key, "must be an array of tables", "Write each entry as [[" + key + "]]");
    out.push_back(Table(t, fmt::format("{}[{}]", path_.empty() ? key : path_ + "." + key, k), file_));
  }
  return out;
}

void Table::finish() const {
  for (const auto& [key, node] : as_table(node_))
    if (!used_->count(std::string(key.str())))
      throw InputError(node.source().begin.line > 0 ? fmt::format("{}:{}", *file_, node.source().begin.line)
                                                    : *file_ + " (--set)",
                       path_.empty() ? std::string(key.str()) : path_ + "." + std::string(key.str()),
                       "unknown key", "Check the spelling; `diefill scene` prints every key with its default");
}

}  // namespace scene
