#include "core/pipeline/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <string>
#include <thread>

namespace tod {
namespace {

Status RunGuarded(const std::function<Status(int)>& body, int i) {
  try {
    return body(i);
  } catch (const std::exception& e) {
    return Status::Internal("frame " + std::to_string(i) + ": " + e.what());
  } catch (...) {
    return Status::Internal("frame " + std::to_string(i) + ": unknown exception");
  }
}

}  // namespace

std::vector<Status> ParallelFor(int count, int threads, const std::function<Status(int)>& body) {
  std::vector<Status> results(std::max(0, count));
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min(threads, count);
  if (threads <= 1) {
    for (int i = 0; i < count; ++i) results[i] = RunGuarded(body, i);
    return results;
  }
  std::atomic<int> next{0};
  {
    std::vector<std::jthread> pool;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back([&] {
        for (int i = next++; i < count; i = next++) results[i] = RunGuarded(body, i);
      });
  }
  return results;
}

}  // namespace tod
