// tod_client: send frames to tod_server over gRPC and save what comes back.
//   tod_client detect --addr HOST:PORT IMAGE|FOLDER ... [--out DIR]   one Detect call per image
//   tod_client stream --addr HOST:PORT IMAGE|FOLDER ... [--out DIR]   all images on one stream
//   tod_client info   --addr HOST:PORT                                 model info as JSON
//   tod_client health --addr HOST:PORT [--service NAME]                exit 0 iff SERVING
// Every command takes --tls-ca FILE (TLS), --tls-cert/--tls-key (mutual TLS) and --token-file.
#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "client/detect_outputs.h"
#include "client/image_files.h"
#include "client/tod_grpc_client.h"
#include "proto/json/message_json.h"

namespace {

struct DetectArgs {
  std::vector<std::string> inputs;
  std::string out_dir;
  int max_proposals = -1;               // -1: server default
  float threshold = -1.f;               // <0: server default
  std::string map = "png";              // png | none
  std::string map_kind = "normalized";  // normalized | calibrated
  int timeout_ms = 0;                   // 0: no deadline
  std::string model;                    // empty: the server's default model
};

tod::v1::DetectRequest MakeRequest(const DetectArgs& args, const std::string& path,
                                   std::string image) {
  tod::v1::DetectRequest request;
  request.set_image(std::move(image));
  request.set_frame_id(path);
  request.set_model(args.model);
  if (args.max_proposals >= 0) request.mutable_options()->set_max_proposals(args.max_proposals);
  if (args.threshold >= 0) request.mutable_options()->set_obstacle_threshold(args.threshold);
  request.mutable_options()->set_map_format(args.map == "none" ? tod::v1::MAP_FORMAT_NONE
                                                               : tod::v1::MAP_FORMAT_PNG);
  request.mutable_options()->set_map_kind(
      args.map_kind == "calibrated" ? tod::v1::MAP_KIND_CALIBRATED : tod::v1::MAP_KIND_NORMALIZED);
  return request;
}

// Writes the outputs for one answered frame, or prints the JSON when no --out was given.
bool Report(const DetectArgs& args, const std::string& path, const std::string& image,
            const tod::v1::DetectResponse& response) {
  if (args.out_dir.empty()) {
    tod::v1::DetectResponse printed = response;
    printed.mutable_probability_map()->clear_png();
    std::cout << tod::proto::MessageToJson(printed, tod::proto::JsonLayout::kIndented) << "\n";
    return true;
  }
  if (const tod::Status s = tod::client::WriteDetectOutputs(args.out_dir, path, image, response);
      !s.ok()) {
    std::cerr << "tod_client: " << s.message() << "\n";
    return false;
  }
  std::cerr << path << ": " << response.obstacles_size() << " obstacles, " << response.total_ms()
            << " ms\n";
  return true;
}

// The connection flags every command shares.
struct ConnectionArgs {
  std::string tls_ca;
  std::string tls_cert;
  std::string tls_key;
  std::string token_file;
};

void AddConnectionOptions(CLI::App* command, ConnectionArgs* args) {
  command->add_option("--tls-ca", args->tls_ca, "PEM CA of the server's certificate: use TLS");
  command->add_option("--tls-cert", args->tls_cert, "PEM client certificate (mutual TLS)");
  command->add_option("--tls-key", args->tls_key, "PEM key of --tls-cert");
  command->add_option("--token-file", args->token_file,
                      "File whose first line is the bearer token to send");
}

// A client for `addr`, or nullopt (with the reason printed) when a flag's file is unusable.
std::optional<tod::client::TodGrpcClient> Connect(const std::string& addr,
                                                  const ConnectionArgs& args) {
  auto options =
      tod::client::LoadConnectionOptions(args.tls_ca, args.tls_cert, args.tls_key, args.token_file);
  if (!options.ok()) {
    std::cerr << "tod_client: " << options.status().message() << "\n";
    return std::nullopt;
  }
  return std::optional<tod::client::TodGrpcClient>(std::in_place, addr, std::move(*options));
}

int RunDetect(const std::string& addr, const ConnectionArgs& connection, const DetectArgs& args,
              bool as_stream) {
  auto images = tod::client::CollectImages(args.inputs);
  if (!images.ok()) {
    std::cerr << "tod_client: " << images.status().message() << "\n";
    return 2;
  }
  std::vector<std::string> bytes;
  for (const std::string& path : *images) {
    auto read = tod::client::ReadFileBytes(path);
    if (!read.ok()) {
      std::cerr << "tod_client: " << read.status().message() << "\n";
      return 2;
    }
    bytes.push_back(std::move(*read));
  }
  std::optional<tod::client::TodGrpcClient> connected = Connect(addr, connection);
  if (!connected) return 2;
  tod::client::TodGrpcClient& client = *connected;
  bool all_ok = true;
  if (as_stream) {
    std::vector<tod::v1::DetectRequest> requests;
    for (size_t i = 0; i < images->size(); ++i) {
      requests.push_back(MakeRequest(args, (*images)[i], bytes[i]));
    }
    size_t answered = 0;
    const grpc::Status status =
        client.DetectStream(requests, [&](const tod::v1::DetectResponse& response) {
          // Responses come in request order; the frame id confirms it.
          if (answered < images->size()) {
            all_ok &= Report(args, (*images)[answered], bytes[answered], response);
          }
          ++answered;
        });
    if (!status.ok() || answered != images->size()) {
      std::cerr << "tod_client: stream ended after " << answered << " of " << images->size()
                << " frames: " << status.error_code() << " " << status.error_message() << "\n";
      return 1;
    }
    return all_ok ? 0 : 1;
  }
  for (size_t i = 0; i < images->size(); ++i) {
    tod::v1::DetectResponse response;
    std::optional<std::chrono::milliseconds> timeout;
    if (args.timeout_ms > 0) timeout = std::chrono::milliseconds(args.timeout_ms);
    const grpc::Status status =
        client.Detect(MakeRequest(args, (*images)[i], bytes[i]), &response, timeout);
    if (!status.ok()) {
      std::cerr << (*images)[i] << ": error " << status.error_code() << ": "
                << status.error_message() << "\n";
      all_ok = false;
      continue;
    }
    all_ok &= Report(args, (*images)[i], bytes[i], response);
  }
  return all_ok ? 0 : 1;
}

int RunInfo(const std::string& addr, const ConnectionArgs& connection, const std::string& model) {
  std::optional<tod::client::TodGrpcClient> client = Connect(addr, connection);
  if (!client) return 2;
  tod::v1::ModelInfo info;
  const grpc::Status status = client->GetModelInfo(&info, std::chrono::seconds(10), model);
  if (!status.ok()) {
    std::cerr << "tod_client: GetModelInfo failed: " << status.error_code() << " "
              << status.error_message() << "\n";
    return 1;
  }
  std::cout << tod::proto::MessageToJson(info, tod::proto::JsonLayout::kIndented) << "\n";
  return 0;
}

// Exit 0 when SERVING, 1 otherwise (Docker HEALTHCHECK reserves other codes).
int RunHealth(const std::string& addr, const ConnectionArgs& connection,
              const std::string& service) {
  std::optional<tod::client::TodGrpcClient> client = Connect(addr, connection);
  if (!client) return 1;  // not 2: Docker's HEALTHCHECK reserves it
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = client->Health(service, &response);
  if (!status.ok()) {
    std::cout << "UNREACHABLE " << status.error_code() << " " << status.error_message() << "\n";
    return 1;
  }
  std::cout << grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status()) << "\n";
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING ? 0 : 1;
}

void AddDetectOptions(CLI::App* command, std::string* addr, DetectArgs* args) {
  command->add_option("--addr", *addr, "Server gRPC address HOST:PORT")->required();
  command->add_option("inputs", args->inputs, "Image files or folders")->required();
  command->add_option("--out", args->out_dir,
                      "Folder for <stem>.json, <stem>.map.png, <stem>.overlay.png "
                      "(default: print JSON)");
  command->add_option("--max-proposals", args->max_proposals, "Proposals returned");
  command->add_option("--threshold", args->threshold, "Obstacle threshold on P");
  command->add_option("--map", args->map, "png | none")->check(CLI::IsMember({"png", "none"}));
  command
      ->add_option("--map-kind", args->map_kind,
                   "normalized (the paper's map, peak 1 on every frame) | calibrated")
      ->check(CLI::IsMember({"normalized", "calibrated"}));
  command->add_option("--timeout-ms", args->timeout_ms, "gRPC deadline per request (0: none)");
  command->add_option("--model", args->model,
                      "The model to run, by name (a bundle of the server's --model-repository; "
                      "default: the server's default model)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tod_client: talk to tod_server over gRPC"};
  app.require_subcommand(1);
  std::string addr;
  DetectArgs detect_args;
  DetectArgs stream_args;
  std::string service;
  std::string info_model;
  ConnectionArgs connection;

  CLI::App* detect = app.add_subcommand("detect", "Detect obstacles, one request per image");
  AddDetectOptions(detect, &addr, &detect_args);
  CLI::App* stream = app.add_subcommand("stream", "Detect on one bidirectional stream, in order");
  AddDetectOptions(stream, &addr, &stream_args);
  CLI::App* info = app.add_subcommand("info", "Print the serving model's info");
  info->add_option("--addr", addr, "Server gRPC address HOST:PORT")->required();
  info->add_option("--model", info_model, "The model, by name (default: the server's default)");
  CLI::App* health = app.add_subcommand("health", "gRPC health check; exit 0 iff SERVING");
  health->add_option("--addr", addr, "Server gRPC address HOST:PORT")->required();
  health->add_option("--service", service, "Service name (default: whole server)");

  for (CLI::App* command : {detect, stream, info, health}) {
    AddConnectionOptions(command, &connection);
  }

  CLI11_PARSE(app, argc, argv);
  if (*detect) return RunDetect(addr, connection, detect_args, /*as_stream=*/false);
  if (*stream) return RunDetect(addr, connection, stream_args, /*as_stream=*/true);
  if (*info) return RunInfo(addr, connection, info_model);
  return RunHealth(addr, connection, service);
}
