// Runs the real tod_server binary for end-to-end tests: free loopback ports, a log file, signals,
// readiness polling, and helpers to read the Prometheus text.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace httplib {
class Client;
}  // namespace httplib

namespace tod::server::testing {

// How the harness's own HTTP client reaches a server started with TLS (empty: plain HTTP).
struct HarnessTls {
  std::string ca_cert;
  std::string client_cert;  // for servers that require client certificates
  std::string client_key;
};

// A TCP port on 127.0.0.1 that was free a moment ago.
int FreeLoopbackPort();

// <bin dir>/<name> (tests/test_env.h: configured, or $TOD_BIN_DIR).
std::string BinaryPath(const std::string& name);

// The tiny model bundle of the CTest fixture (tiny_model), or "" when it does not exist.
std::string TestModel();

// A fresh empty directory under the system temp directory.
std::string MakeTempDir(const std::string& prefix);

struct ProcessResult {
  int exit_code = -1;  // -1: killed by a signal or still running
  std::string output;  // stdout + stderr
};

// Runs a command to completion (stdout+stderr captured); for tod_client / tod_load.
ProcessResult RunCommand(const std::vector<std::string>& argv);

class ServerProcess {
 public:
  // Starts tod_server --model DIR (none when `model_dir` is empty: `extra_args` then say what to
  // serve) on ports the kernel picks, plus `extra_args`; returns once the server listens (its
  // ports are known) or has exited.
  static std::unique_ptr<ServerProcess> Start(const std::string& model_dir,
                                              const std::vector<std::string>& extra_args,
                                              HarnessTls tls = {});
  ~ServerProcess();  // SIGKILL if still running

  // Polls GET /v2/health/ready until 200; false if the process exits or `timeout` passes.
  bool WaitReady(std::chrono::milliseconds timeout = std::chrono::seconds(60));
  void Signal(int signal_number) const;
  // Exit code once the process ends (within `timeout`), else nullopt.
  std::optional<int> WaitExit(std::chrono::milliseconds timeout);
  std::string Log() const;
  // An HTTP(S) client of this server's REST port (HTTPS with the harness's TLS files).
  std::unique_ptr<httplib::Client> HttpClient() const;
  // GET /metrics through HttpClient() ("" on failure).
  std::string Metrics() const;
  // Polls the metrics until `series` is at least `value`; false after `timeout`.
  bool WaitForMetric(const std::string& series, double value,
                     std::chrono::milliseconds timeout = std::chrono::seconds(60)) const;

  pid_t pid() const { return pid_; }
  int grpc_port() const { return grpc_port_; }
  int http_port() const { return http_port_; }
  std::string grpc_address() const { return "127.0.0.1:" + std::to_string(grpc_port_); }

 private:
  ServerProcess() = default;
  // Waits for tod_server's --ports-file and takes the ports it bound from it.
  void ReadPorts(const std::string& ports_file);
  pid_t pid_ = -1;
  int grpc_port_ = 0;
  int http_port_ = 0;
  std::string log_path_;
  std::optional<int> exit_code_;
  HarnessTls tls_;
};

// GET /metrics from the server as text ("" on failure).
std::string ScrapeMetrics(int http_port);
// Value of the first sample whose line starts with `series` (name + labels as printed),
// e.g. `tod_rejections_total{reason="deadline"}`; nullopt when absent.
std::optional<double> MetricValue(const std::string& metrics_text, const std::string& series);

}  // namespace tod::server::testing

// End-to-end tests need the fixture's model and the built server. Missing ones are a failure,
// not a skip: a broken fixture must not turn the service tests green.
#define REQUIRE_MODEL()                                                                   \
  if (::tod::server::testing::TestModel().empty() ||                                      \
      !std::filesystem::exists(::tod::server::testing::BinaryPath("tod_server"))) {       \
    GTEST_FAIL() << "no test model bundle or tod_server (run through ctest, which makes " \
                    "the tiny_model fixture)";                                            \
  }
