#include "server/oip/oip_base64.h"

#include <array>
#include <cstdint>

namespace tod::server::oip {
namespace {

constexpr std::string_view kAlphabet =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
constexpr uint8_t kInvalid = 0xff;

// Character -> 6-bit value, kInvalid for everything outside the alphabet ('=' included: padding
// is stripped before decoding).
constexpr std::array<uint8_t, 256> MakeDecodeTable() {
  std::array<uint8_t, 256> table{};
  table.fill(kInvalid);
  for (size_t i = 0; i < kAlphabet.size(); ++i) {
    table[static_cast<unsigned char>(kAlphabet[i])] = static_cast<uint8_t>(i);
  }
  return table;
}
constexpr std::array<uint8_t, 256> kDecode = MakeDecodeTable();

}  // namespace

std::string Base64Encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const uint32_t group = static_cast<uint32_t>(static_cast<unsigned char>(bytes[i])) << 16 |
                           static_cast<uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8 |
                           static_cast<uint32_t>(static_cast<unsigned char>(bytes[i + 2]));
    out += kAlphabet[(group >> 18) & 63];
    out += kAlphabet[(group >> 12) & 63];
    out += kAlphabet[(group >> 6) & 63];
    out += kAlphabet[group & 63];
  }
  const size_t rest = bytes.size() - i;
  if (rest > 0) {
    uint32_t group = static_cast<uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (rest == 2) group |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out += kAlphabet[(group >> 18) & 63];
    out += kAlphabet[(group >> 12) & 63];
    out += rest == 2 ? kAlphabet[(group >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

Result<std::string> Base64Decode(std::string_view text, size_t max_decoded_bytes) {
  // At most two '=' and only at the end; after them the length must be a whole number of
  // 4-character groups when padded, and never leave a lone character (6 bits are no byte).
  const bool padded = !text.empty() && text.back() == '=';
  std::string_view body = text;
  while (!body.empty() && body.back() == '=' && text.size() - body.size() < 2) {
    body.remove_suffix(1);
  }
  if ((padded && text.size() % 4 != 0) || body.size() % 4 == 1) {
    return Status::InvalidArgument("base64 text of " + std::to_string(text.size()) +
                                   " characters has an impossible length or padding");
  }
  const size_t decoded_size =
      body.size() / 4 * 3 + (body.size() % 4 == 0 ? 0 : body.size() % 4 - 1);
  if (decoded_size > max_decoded_bytes) {
    return Status::ResourceExhausted("base64 data decodes to " + std::to_string(decoded_size) +
                                     " bytes, over the limit of " +
                                     std::to_string(max_decoded_bytes) + " bytes");
  }
  std::string out;
  out.reserve(decoded_size);
  uint32_t group = 0;
  int bits = 0;
  for (size_t i = 0; i < body.size(); ++i) {
    const uint8_t value = kDecode[static_cast<unsigned char>(body[i])];
    if (value == kInvalid) {
      return Status::InvalidArgument("base64 text has an invalid character at offset " +
                                     std::to_string(i));
    }
    group = (group << 6) | value;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((group >> bits) & 0xff);
    }
  }
  return out;
}

}  // namespace tod::server::oip
