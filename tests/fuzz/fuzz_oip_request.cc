// Fuzzes the Open Inference Protocol's request parsers, the bodies a client sends to
// POST /v2/models/{name}/infer and to ModelInfer: the first byte picks
//   0: a REST body, all JSON (ParseInferRequest without the binary extension);
//   1: a REST body with Inference-Header-Content-Length (the next two bytes, as its decimal
//      text), JSON then binary tensor data;
//   2: a gRPC ModelInferRequest (protobuf), then FromModelInferRequest.
// Besides memory safety it checks the bounds the parsers promise: an accepted image is within the
// image limit and inside the bytes it came from, and at most max_outputs outputs are listed.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "inference/grpc_service.pb.h"
#include "server/oip/oip_grpc_messages.h"
#include "server/oip/oip_tensors.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;
using tod::server::oip::BodyLimits;
using tod::server::oip::InferRequest;

// Small limits so that the fuzzer reaches them; the server's image limit is 16 MiB.
constexpr BodyLimits kLimits{.max_image_bytes = 4096};

bool Inside(std::string_view part, std::string_view whole) {
  return part.empty() ||
         (part.data() >= whole.data() && part.data() + part.size() <= whole.data() + whole.size());
}

void CheckAccepted(const InferRequest& request) {
  Check(request.image().size() <= kLimits.max_image_bytes);
  Check(request.outputs.size() <= kLimits.max_outputs);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tod::fuzz::Bytes bytes(data, size);
  const int mode = bytes.U8() % 3;
  if (mode == 2) {
    inference::ModelInferRequest message;
    if (!message.ParseFromArray(bytes.rest(), static_cast<int>(bytes.left()))) return 0;
    const auto parsed = tod::server::oip::FromModelInferRequest(message, kLimits);
    if (parsed.ok()) CheckAccepted(*parsed);
    return 0;
  }
  std::string header_length;
  if (mode == 1) header_length = std::to_string(bytes.U8() | bytes.U8() << 8);
  const std::string_view body(reinterpret_cast<const char*>(bytes.rest()), bytes.left());
  const auto parsed = tod::server::oip::ParseInferRequest(
      body, mode == 1 ? std::optional<std::string_view>(header_length) : std::nullopt, kLimits);
  if (!parsed.ok()) return 0;
  CheckAccepted(*parsed);
  if (parsed->binary_image) Check(Inside(*parsed->binary_image, body));
  return 0;
}
