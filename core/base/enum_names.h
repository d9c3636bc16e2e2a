// Choices with names: each enum lists its values and their names once, in a specialisation of
// EnumNames, and every parse, print and CLI check goes through that one table. A choice compared
// as a string in several files drifts (a new value parsed in one place, printed as "?" in
// another); a table of its own cannot.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tod {

// Specialise with `static constexpr std::array<std::pair<E, std::string_view>, N> kTable`.
template <typename E>
struct EnumNames;

template <typename E>
std::string_view EnumName(E value) {
  for (const auto& [v, name] : EnumNames<E>::kTable)
    if (v == value) return name;
  return "?";
}

// The same as a std::string (for JSON and messages).
template <typename E>
std::string EnumString(E value) {
  return std::string(EnumName(value));
}

template <typename E>
std::optional<E> ParseEnum(std::string_view name) {
  for (const auto& [v, n] : EnumNames<E>::kTable)
    if (n == name) return v;
  return std::nullopt;
}

// Every name, in the table's order (for CLI11's IsMember and for messages).
template <typename E>
std::vector<std::string> EnumNameList() {
  std::vector<std::string> names;
  for (const auto& entry : EnumNames<E>::kTable) names.emplace_back(entry.second);
  return names;
}

// "a, b or c", for messages.
template <typename E>
std::string EnumNamesInWords() {
  const std::vector<std::string> names = EnumNameList<E>();
  std::string words;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) words += i + 1 == names.size() ? " or " : ", ";
    words += names[i];
  }
  return words;
}

}  // namespace tod
