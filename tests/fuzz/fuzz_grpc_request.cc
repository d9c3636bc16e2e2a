// Fuzzes the gRPC front end's request handling, minus the transport: the bytes arrive as a
// grpc::ByteBuffer (as the raw methods receive them) and go through what SubmitFrame does before
// a worker runs: ParseMessage into tod.v1.DetectRequest, OptionsFromProto, then the engine's
// admission checks (option ranges, byte limit, image header, pixel limit) in Submit. The engine
// has a model installed but a queue of capacity 0 and no workers, so every request either is
// refused for a reason of its own or reaches the queue (answered "queue full"), inline.
// GetModelInfo's request parsing and the JSON printing of the parsed message are fuzzed as well.
#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/slice.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include "core/pipeline/detector.h"
#include "proto/json/message_json.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/detect_response.h"
#include "server/grpc_messages.h"
#include "tests/fuzz/fuzz_util.h"
#include "tod/v1/obstacle_discovery.pb.h"

namespace {

using tod::fuzz::Check;

// Never runs: nothing is admitted past the queue.
class UnusedDetector final : public tod::Detector {
 public:
  tod::Result<tod::Detection> Detect(const cv::Mat3b&, const tod::DetectOptions&) const override {
    std::abort();
  }
  const tod::ModelInfo& info() const override { return info_; }

 private:
  tod::ModelInfo info_;
};

struct Engine {
  tod::server::ModelHolder models;
  std::unique_ptr<tod::server::InferenceEngine> engine;
  Engine() {
    models.Install(std::make_shared<UnusedDetector>(), "fuzz");
    tod::server::EngineConfig config;
    config.workers = 0;
    config.queue_capacity = 0;
    config.limits.max_bytes = 1 << 16;
    config.limits.max_pixels = 1 << 20;
    engine = std::make_unique<tod::server::InferenceEngine>(config, models, nullptr);
  }
};

}  // namespace

// model_holder.cc loads bundles through Detector::Load, which is the whole detection pipeline;
// this target never loads one (it installs UnusedDetector), so a stand-in keeps the pipeline out
// of the fuzz build.
tod::Result<std::shared_ptr<const tod::Detector>> tod::Detector::Load(const std::string&) {
  return tod::Status::FailedPrecondition("no model loading in fuzz_grpc_request");
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Engine* const engine = new Engine();  // lives for the whole run, as the server's does

  grpc::Slice slice(data, size);
  const grpc::ByteBuffer bytes(&slice, 1);

  tod::v1::GetModelInfoRequest info_request;
  (void)tod::server::ParseMessage(bytes, &info_request);

  tod::v1::DetectRequest request;
  const tod::Status parsed = tod::server::ParseMessage(bytes, &request);
  if (!parsed.ok()) {
    Check(!parsed.message().empty());
    return 0;
  }
  (void)tod::proto::MessageToJson(request);

  const tod::server::RequestOptions options = tod::server::OptionsFromProto(request.options());
  tod::server::InferenceRequest inference;
  inference.image = request.image();
  inference.options = options.detect;
  inference.encode_map_png = options.encode_map_png;
  int completions = 0;
  engine->engine->Submit(inference, [&](tod::server::InferenceResult result) {
    ++completions;
    Check(!result.status.ok() && result.rejection != tod::server::Rejection::kNone);
    if (result.rejection == tod::server::Rejection::kQueueFull) {  // passed every check
      Check(inference.options.max_proposals >= 0 && inference.options.max_proposals <= 10000);
      Check(inference.options.obstacle_threshold >= 0.f &&
            inference.options.obstacle_threshold <= 1.f);
      Check(!inference.image.empty() && inference.image.size() <= (1u << 16));
    }
  });
  Check(completions == 1);  // answered exactly once, inline
  return 0;
}
