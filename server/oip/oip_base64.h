// Base64 (RFC 4648, standard alphabet) for the BYTES tensors of the JSON form of the Open
// Inference Protocol: JSON strings cannot carry an encoded image's raw bytes, so an image in a
// JSON body, and a PNG map in a JSON answer, travel base64-encoded.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod::server::oip {

std::string Base64Encode(std::string_view bytes);

// Padding is optional ("QQ" and "QQ==" both decode to "A"); whitespace, other alphabets (URL-safe)
// and stray characters are InvalidArgument. The decoded size is worked out from the text's length
// and checked against `max_decoded_bytes` (ResourceExhausted) before any output is allocated.
Result<std::string> Base64Decode(std::string_view text, size_t max_decoded_bytes);

}  // namespace tod::server::oip
