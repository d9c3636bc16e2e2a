// What the inference engine reports while it works, to whoever counts it: the server's metrics
// (ServerMetrics, server/metrics.h) in production, a recorder in tests. The engine knows nothing
// of Prometheus; it calls these from the submitting thread or a worker, some of them with its
// queue lock held, so an observer must be thread-safe, quick, and must not call into the engine.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/pipeline/detector.h"
#include "server/core/cancellation.h"
#include "server/core/rejection.h"

namespace tod::server {

class EngineObserver {
 public:
  virtual ~EngineObserver() = default;

  // A request passed admission and took a queue slot; `queue_depth` now waiting, it included.
  virtual void OnAccepted(size_t queue_depth) = 0;
  // The queue changed size otherwise: a worker took a request, or the drain timeout emptied it.
  virtual void OnQueueDepth(size_t queue_depth) = 0;
  // A worker began an accepted request after it had waited `queue_ms` in the queue.
  virtual void OnStarted(double queue_ms) = 0;
  // An accepted request left the engine; its answer goes out right after this call (so a
  // client that has its answer never sees its request still in flight).
  virtual void OnFinished() = 0;
  // A request (accepted or refused at admission) is answered with `rejection` (never kNone).
  virtual void OnRejected(Rejection rejection) = 0;
  // The work of a request was stopped or skipped for `reason` (also reported as a rejection).
  virtual void OnCancelled(CancelReason reason) = 0;
  // A request produced `detection` with the model named `model`: its stage times in ms
  // ("queue", "decode", the pipeline's stages, "encode_map"); the detection says which stages
  // its frame budget cut short and where its geometry came from.
  virtual void OnDetected(const std::string& model, const StageTimes& timings,
                          const Detection& detection) = 0;
  // The cameras whose horizon the engine keeps, after a detection.
  virtual void OnCameras(size_t cameras) = 0;
};

}  // namespace tod::server
