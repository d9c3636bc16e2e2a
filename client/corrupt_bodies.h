// Damaged request bodies for load tests (tod_load --corrupt): what a broken camera, an upload cut
// short or a confused client sends. The server must refuse each with 400, cheaply, and go on.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace tod::client {

struct RequestBody {
  std::string name;  // what was done to it, e.g. "truncated JPEG"
  std::string bytes;
  std::string content_type;
};

// From one valid frame (PNG or JPEG bytes): its JPEG and its PNG encodings each cut in half, and as
// many bytes of noise (from `seed`) sent as a PNG. A frame that does not decode gives the noise
// only.
std::vector<RequestBody> CorruptBodies(const std::string& frame_bytes, uint32_t seed);

}  // namespace tod::client
