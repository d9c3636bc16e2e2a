// Integer fields read from JSON (manifest.json). nlohmann's get<int>() and the
// NLOHMANN_DEFINE_TYPE readers cast whatever number they find to the field's type: a float outside
// its range is undefined behaviour (fuzz_manifest: a region corner of 1.11e23 read as an int,
// docs/service.md#found-and-fixed), an integer outside it wraps silently. These check a value
// before it is converted.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "core/base/status.h"

namespace tod {

// True when `value` is a JSON integer (not a float, however integral) that fits an int.
bool IsJsonInt(const nlohmann::json& value);

// The int in `value`, or InvalidArgument naming `what`.
Result<int> JsonToInt(const nlohmann::json& value, const std::string& what);

// Every member of `input` whose counterpart in `defaults` (the same struct written with its default
// values) is an integer must be an integer of the same kind: signed (the structs' int fields) and
// within int's range, or unsigned (their uint64_t fields) and not negative. Nested objects are
// checked member by member; members missing on either side are left to the reader. InvalidArgument
// naming the member (`where` + its path) otherwise.
Status CheckJsonIntegers(const nlohmann::json& input, const nlohmann::json& defaults,
                         const std::string& where);

}  // namespace tod
