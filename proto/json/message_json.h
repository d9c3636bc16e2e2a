// The JSON form of the tod.v1 messages, one conversion for every program that prints them: the
// REST front end answers with the compact layout, tod_client writes and prints the indented one.
// Proto3 JSON with the .proto field names (frame_id, not frameId) and fields at their default
// value printed; bytes fields become base64, enums their value names (MAP_KIND_CALIBRATED).
// These keys are the REST API (docs and tests/server/proto_json_test.cc pin them).
#pragma once

#include <google/protobuf/message.h>

#include <string>

namespace tod::proto {

enum class JsonLayout {
  kCompact,   // one line, no spaces
  kIndented,  // one field per line, one space per level, ending with a newline
};

// Printing a valid message cannot fail; "{}" is the fallback if it ever did.
std::string MessageToJson(const google::protobuf::Message& message,
                          JsonLayout layout = JsonLayout::kCompact);

}  // namespace tod::proto
