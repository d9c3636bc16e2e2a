// tod_load: load generator for tod_server over gRPC or HTTP.
//   closed loop (--concurrency N): N senders, each sends its next request as soon as the previous
//     one is answered;
//   open loop (--rate R): requests are scheduled at fixed times R per second and latency is
//     measured from the scheduled time, so a slow server cannot hide queueing by slowing the
//     sender down (no coordinated omission). --concurrency is then the number of senders.
// Requests cycle through the images of --images; the first --warmup seconds are not measured.
// --corrupt sends damaged versions of the images instead (truncated JPEG and PNG, noise), for
// soak tests that mix bad requests into the load (deploy/soak.sh).
#include <httplib.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cctype>
#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "client/corrupt_bodies.h"
#include "client/detect_outputs.h"
#include "client/image_files.h"
#include "client/load_stats.h"
#include "client/tod_grpc_client.h"

namespace {

using Clock = std::chrono::steady_clock;
// --corrupt: damaged versions of this many frames are enough variety (each takes a decode and two
// encodes at start-up).
constexpr size_t kCorruptFrames = 8;

struct LoadArgs {
  std::string addr;
  std::string images_dir;
  bool http = false;
  bool corrupt = false;
  int concurrency = 4;
  double rate = 0;  // > 0: open loop
  double duration_s = 10;
  double warmup_s = 1;
  std::string json_path;
  std::string map = "none";
  int timeout_ms = 30000;
  std::string model;   // empty: the server's default model
  std::string tls_ca;  // TLS (HTTPS / gRPC over TLS) when set
  std::string tls_cert;
  std::string tls_key;
  std::string token_file;
  tod::client::ConnectionOptions connection;  // the files above, read
};

struct Image {
  std::string path;
  std::string bytes;
  std::string content_type;
};

// `text` with every byte but the unreserved ones %-escaped, for a query value.
std::string QueryEscaped(const std::string& text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string escaped;
  for (const unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      escaped.push_back(static_cast<char>(c));
    } else {
      escaped += {'%', kHex[c >> 4], kHex[c & 15]};
    }
  }
  return escaped;
}

// One sender's connection; gRPC channels are shared, HTTP clients are per thread.
class Sender {
 public:
  Sender(const LoadArgs& args, tod::client::TodGrpcClient* grpc) : args_(args), grpc_(grpc) {
    if (args.http) {
      const tod::client::ConnectionOptions& connection = args.connection;
      if (connection.tls_ca_file.empty()) {
        http_ = std::make_unique<httplib::Client>("http://" + args.addr);
      } else {
        http_ = std::make_unique<httplib::Client>("https://" + args.addr, connection.tls_cert_file,
                                                  connection.tls_key_file);
        http_->set_ca_cert_path(connection.tls_ca_file.c_str());
        http_->enable_server_certificate_verification(true);
      }
      if (!connection.token.empty()) http_->set_bearer_token_auth(connection.token.c_str());
      http_->set_read_timeout(std::chrono::milliseconds(args.timeout_ms));
      http_->set_write_timeout(std::chrono::milliseconds(args.timeout_ms));
      http_->set_keep_alive(true);
    }
  }

  tod::client::LoadSample Send(const Image& image, Clock::time_point measured_from) {
    tod::client::LoadSample sample;
    if (http_) {
      const std::string path = "/v1/detect?map=" + args_.map +
                               (args_.model.empty() ? "" : "&model=" + QueryEscaped(args_.model));
      const httplib::Result result =
          http_->Post(path.c_str(), image.bytes, image.content_type.c_str());
      if (result) {
        sample.code = std::to_string(result->status);
        sample.ok = result->status == 200;
      } else {
        sample.code = "transport_" + httplib::to_string(result.error());
      }
    } else {
      tod::v1::DetectRequest request;
      request.set_image(image.bytes);
      request.set_model(args_.model);
      request.mutable_options()->set_map_format(args_.map == "png" ? tod::v1::MAP_FORMAT_PNG
                                                                   : tod::v1::MAP_FORMAT_NONE);
      tod::v1::DetectResponse response;
      const grpc::Status status =
          grpc_->Detect(request, &response, std::chrono::milliseconds(args_.timeout_ms));
      sample.code = CodeName(status.error_code());
      sample.ok = status.ok();
    }
    sample.latency_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - measured_from).count();
    return sample;
  }

 private:
  static std::string CodeName(grpc::StatusCode code) {
    switch (code) {
      case grpc::StatusCode::OK:
        return "OK";
      case grpc::StatusCode::INVALID_ARGUMENT:
        return "INVALID_ARGUMENT";
      case grpc::StatusCode::DEADLINE_EXCEEDED:
        return "DEADLINE_EXCEEDED";
      case grpc::StatusCode::RESOURCE_EXHAUSTED:
        return "RESOURCE_EXHAUSTED";
      case grpc::StatusCode::UNAVAILABLE:
        return "UNAVAILABLE";
      case grpc::StatusCode::INTERNAL:
        return "INTERNAL";
      case grpc::StatusCode::UNAUTHENTICATED:
        return "UNAUTHENTICATED";
      default:
        return std::string("CODE_") + std::to_string(static_cast<int>(code));
    }
  }

  const LoadArgs& args_;
  tod::client::TodGrpcClient* grpc_;
  std::unique_ptr<httplib::Client> http_;
};

// The command line; returns the --concurrency option, whose default depends on the loop.
CLI::Option* AddLoadOptions(CLI::App& app, LoadArgs& args) {
  app.add_option("--addr", args.addr, "Server address HOST:PORT (gRPC port, or HTTP with --http)")
      ->required();
  app.add_option("--images", args.images_dir, "Folder of .png/.jpg frames to cycle through")
      ->required();
  app.add_flag("--http", args.http, "Use REST POST /v1/detect instead of gRPC");
  app.add_flag("--corrupt", args.corrupt,
               "Send damaged images instead (each of the first 8: its JPEG and PNG cut in half, "
               "noise of its size); the server must answer each with 400 / INVALID_ARGUMENT");
  auto* concurrency = app.add_option("--concurrency", args.concurrency,
                                     "Closed loop: requests in flight; open loop: senders")
                          ->check(CLI::Range(1, 4096));
  app.add_option("--rate", args.rate, "Open loop: requests per second (0: closed loop)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--duration", args.duration_s, "Measured seconds (default 10)")
      ->check(CLI::PositiveNumber);
  app.add_option("--warmup", args.warmup_s, "Unmeasured seconds first (default 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--json", args.json_path, "Also write the report as JSON to FILE");
  app.add_option("--map", args.map, "Probability map: none | png (default none)")
      ->check(CLI::IsMember({"png", "none"}));
  app.add_option("--model", args.model,
                 "The model, by name (a bundle of the server's --model-repository; default: the "
                 "server's default model)");
  app.add_option("--timeout-ms", args.timeout_ms, "Per-request timeout (default 30000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--tls-ca", args.tls_ca, "PEM CA of the server's certificate: use TLS");
  app.add_option("--tls-cert", args.tls_cert, "PEM client certificate (mutual TLS)");
  app.add_option("--tls-key", args.tls_key, "PEM key of --tls-cert");
  app.add_option("--token-file", args.token_file,
                 "File whose first line is the bearer token to send");
  return concurrency;
}

// The request bodies to cycle through: the frames as they are, or (--corrupt) damaged versions
// of the first kCorruptFrames.
tod::Result<std::vector<Image>> LoadImages(const LoadArgs& args) {
  auto paths = tod::client::CollectImages({args.images_dir});
  if (!paths.ok()) return paths.status();
  std::vector<Image> images;
  size_t corrupted_frames = 0;
  for (const std::string& path : *paths) {
    if (args.corrupt && corrupted_frames == kCorruptFrames) break;
    auto bytes = tod::client::ReadFileBytes(path);
    if (!bytes.ok()) return bytes.status();
    if (!args.corrupt) {
      images.push_back({path, std::move(*bytes), tod::client::ContentTypeFor(path)});
      continue;
    }
    for (tod::client::RequestBody& body :
         tod::client::CorruptBodies(*bytes, static_cast<uint32_t>(corrupted_frames++))) {
      images.push_back({path + " (" + body.name + ")", std::move(body.bytes), body.content_type});
    }
  }
  return images;
}

struct LoadRun {
  std::vector<tod::client::LoadSample> samples;  // those scheduled after the warm-up
  double measured_s = 0;
};

// Runs the senders for warm-up plus duration. Closed loop: each sends again when answered;
// open loop: sender t takes the slots t, t + N, ... of the fixed schedule.
LoadRun RunSenders(const LoadArgs& args, const std::vector<Image>& images,
                   tod::client::TodGrpcClient& grpc_client) {
  const bool open_loop = args.rate > 0;
  const Clock::time_point start = Clock::now();
  const Clock::time_point measure_from =
      start + std::chrono::microseconds(static_cast<long long>(args.warmup_s * 1e6));
  const Clock::time_point end =
      measure_from + std::chrono::microseconds(static_cast<long long>(args.duration_s * 1e6));
  std::atomic<long long> next_image{0};
  std::mutex samples_mutex;
  LoadRun run;

  std::vector<std::thread> threads;
  for (int t = 0; t < args.concurrency; ++t) {
    threads.emplace_back([&, t] {
      Sender sender(args, &grpc_client);
      std::vector<tod::client::LoadSample> mine;
      for (long long slot = t;; slot += args.concurrency) {
        Clock::time_point scheduled = Clock::now();
        if (open_loop) {
          scheduled = start + std::chrono::microseconds(static_cast<long long>(
                                  static_cast<double>(slot) * 1e6 / args.rate));
          if (scheduled >= end) break;
          std::this_thread::sleep_until(scheduled);
        } else if (scheduled >= end) {
          break;
        }
        const Image& image = images[next_image++ % images.size()];
        const tod::client::LoadSample sample = sender.Send(image, scheduled);
        if (scheduled >= measure_from) mine.push_back(sample);
      }
      std::lock_guard lock(samples_mutex);
      run.samples.insert(run.samples.end(), mine.begin(), mine.end());
    });
  }
  for (std::thread& thread : threads) thread.join();
  // Closed loop: the window closes when the last in-flight request returns.
  run.measured_s =
      open_loop ? args.duration_s
                : std::chrono::duration<double>(std::max(Clock::now(), end) - measure_from).count();
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tod_load: load generator for tod_server (gRPC or HTTP)"};
  LoadArgs args;
  CLI::Option* concurrency = AddLoadOptions(app, args);
  CLI11_PARSE(app, argc, argv);
  auto connection =
      tod::client::LoadConnectionOptions(args.tls_ca, args.tls_cert, args.tls_key, args.token_file);
  if (!connection.ok()) {
    std::cerr << "tod_load: " << connection.status().message() << "\n";
    return 2;
  }
  args.connection = std::move(*connection);
  const bool open_loop = args.rate > 0;
  if (open_loop && concurrency->count() == 0) args.concurrency = 64;
  const auto images = LoadImages(args);
  if (!images.ok()) {
    std::cerr << "tod_load: " << images.status().message() << "\n";
    return 2;
  }

  tod::client::TodGrpcClient grpc_client(args.addr, args.connection);
  const LoadRun run = RunSenders(args, *images, grpc_client);
  tod::client::LoadReport report = tod::client::Summarize(run.samples, run.measured_s);
  report.protocol = args.http ? "http" : "grpc";
  report.mode = open_loop ? "open" : "closed";
  report.concurrency = args.concurrency;
  report.rate = args.rate;
  std::cout << tod::client::FormatTable(report);
  if (!args.json_path.empty()) {
    const tod::Status written = tod::client::WriteFileBytes(
        args.json_path, tod::client::ReportToJson(report).dump(2) + "\n");
    if (!written.ok()) {
      std::cerr << "tod_load: " << written.message() << "\n";
      return 1;
    }
  }
  return report.requests > 0 ? 0 : 1;
}
