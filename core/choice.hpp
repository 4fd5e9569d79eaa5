#pragma once
// A choice's names and values in one table, next to the enum it names (geometry::length_units,
// mesh::wall_roles, scene::density_methods, ...): the parser, the printed name, the scene key's
// list of choices and its documentation all read that table, so that they cannot disagree.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace diefill {

template <class Value>
struct Choice {
  std::string_view name;
  Value value;
};

template <class Value, std::size_t N>
constexpr std::optional<Value> find_choice(const std::array<Choice<Value>, N>& table, std::string_view name) {
  for (const Choice<Value>& c : table)
    if (c.name == name) return c.value;
  return std::nullopt;
}

template <class Value, std::size_t N>
constexpr std::string_view choice_name(const std::array<Choice<Value>, N>& table, Value value) {
  for (const Choice<Value>& c : table)
    if (c.value == value) return c.name;
  return "?";
}

// "a, b or c"
template <class Value, std::size_t N>
std::string choice_list(const std::array<Choice<Value>, N>& table) {
  std::string list;
  for (std::size_t k = 0; k < N; ++k) list += (k == 0 ? "" : k + 1 == N ? " or " : ", ") + std::string(table[k].name);
  return list;
}

// The value named `text` in a choice's table; InputError naming `field` (a flag or a key) when it
// names none.
template <class Value, std::size_t N>
Value parse_choice(const std::array<Choice<Value>, N>& table, std::string_view text, std::string_view field) {
  if (const auto value = find_choice(table, text)) return *value;
  throw InputError("", std::string(field), "'" + std::string(text) + "' is not one of its choices", "Use " + choice_list(table));
}

}  // namespace diefill
