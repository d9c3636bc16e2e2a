#include "core/pipeline/json_integers.h"

#include <cstdint>
#include <limits>
#include <string>

namespace tod {
namespace {

// A number as written, anything else by its type (an error message must not copy a whole object).
std::string Describe(const nlohmann::json& value) {
  return value.is_number() ? value.dump() : std::string("a ") + value.type_name();
}

bool IsJsonUint64(const nlohmann::json& value) {
  return value.is_number_unsigned() ||
         (value.is_number_integer() && value.get<std::int64_t>() >= 0);
}

}  // namespace

bool IsJsonInt(const nlohmann::json& value) {
  // nlohmann keeps non-negative integers as unsigned and negative ones as signed 64-bit.
  if (value.is_number_unsigned()) {
    return value.get<std::uint64_t>() <= std::uint64_t{std::numeric_limits<int>::max()};
  }
  if (!value.is_number_integer()) return false;
  const std::int64_t v = value.get<std::int64_t>();
  return v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max();
}

Result<int> JsonToInt(const nlohmann::json& value, const std::string& what) {
  if (!IsJsonInt(value)) {
    return Status::InvalidArgument(what + ": " + Describe(value) +
                                   " is not an integer in int's range");
  }
  return value.get<int>();
}

Status CheckJsonIntegers(const nlohmann::json& input, const nlohmann::json& defaults,
                         const std::string& where) {
  if (!input.is_object() || !defaults.is_object()) return Status::Ok();
  for (const auto& [key, expected] : defaults.items()) {
    const auto found = input.find(key);
    if (found == input.end()) continue;
    const std::string name = where + key;
    if (expected.is_object()) {
      if (Status s = CheckJsonIntegers(*found, expected, name + "."); !s.ok()) return s;
    } else if (expected.is_number_unsigned() && !IsJsonUint64(*found)) {
      return Status::InvalidArgument(name + ": " + Describe(*found) +
                                     " is not a non-negative integer");
    } else if (expected.is_number_integer() && !expected.is_number_unsigned()) {
      if (Result<int> v = JsonToInt(*found, name); !v.ok()) return v.status();
    }
  }
  return Status::Ok();
}

}  // namespace tod
