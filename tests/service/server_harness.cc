#include "tests/service/server_harness.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "tests/test_env.h"

extern char** environ;

namespace tod::server::testing {
namespace {

// Spawns argv with stdout+stderr into `log_path`; returns the pid or -1.
pid_t Spawn(const std::vector<std::string>& argv, const std::string& log_path) {
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  // The server blocks its signals itself; start it with a clean mask and default handlers.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = -1;
  // posix_spawnp: a bare name ("curl", "openssl") is looked up on PATH like a shell would.
  if (posix_spawnp(&pid, args[0], &actions, &attributes, args.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  return pid;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int DecodeWaitStatus(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

}  // namespace

int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  socklen_t length = sizeof(address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

std::string TestModel() {
  const std::string model = tod::testing_env::TestModel();
  return std::filesystem::exists(std::filesystem::path(model) / "manifest.json") ? model : "";
}

std::string BinaryPath(const std::string& name) { return tod::testing_env::BinDir() + "/" + name; }

std::string MakeTempDir(const std::string& prefix) {
  static std::mt19937_64 random(std::random_device{}());
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (prefix + "_" + std::to_string(getpid()) + "_" + std::to_string(random() % 1000000007));
  std::filesystem::create_directories(dir);
  return dir.string();
}

ProcessResult RunCommand(const std::vector<std::string>& argv) {
  const std::string log = MakeTempDir("tod_cmd") + "/output.txt";
  ProcessResult result;
  const pid_t pid = Spawn(argv, log);
  if (pid < 0) {
    result.output = "cannot start " + argv[0];
    return result;
  }
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = DecodeWaitStatus(status);
  result.output = ReadAll(log);
  return result;
}

std::unique_ptr<ServerProcess> ServerProcess::Start(const std::string& model_dir,
                                                    const std::vector<std::string>& extra_args,
                                                    HarnessTls tls) {
  std::unique_ptr<ServerProcess> server(new ServerProcess());
  server->tls_ = std::move(tls);
  // The server binds port 0 and says which ports it got: a port picked here and closed again
  // could be taken by a parallel test before the server binds it.
  const std::string dir = MakeTempDir("tod_server");
  server->log_path_ = dir + "/server.log";
  const std::string ports_file = dir + "/ports.json";
  std::vector<std::string> argv = {BinaryPath("tod_server"),
                                   "--host",
                                   "127.0.0.1",
                                   "--grpc-port",
                                   "0",
                                   "--http-port",
                                   "0",
                                   "--ports-file",
                                   ports_file};
  if (!model_dir.empty()) argv.insert(argv.end(), {"--model", model_dir});
  argv.insert(argv.end(), extra_args.begin(), extra_args.end());
  server->pid_ = Spawn(argv, server->log_path_);
  server->ReadPorts(ports_file);
  return server;
}

void ServerProcess::ReadPorts(const std::string& ports_file) {
  // Until the file appears (it is renamed into place whole) or the process ends (a refused
  // configuration: the ports stay 0 and the test reads the exit code and the log).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    std::ifstream in(ports_file);
    if (in) {
      const nlohmann::json ports = nlohmann::json::parse(in, nullptr, false);
      if (ports.is_object()) {
        grpc_port_ = ports.value("grpc", 0);
        http_port_ = ports.value("http", 0);
        return;
      }
    }
    if (WaitExit(std::chrono::milliseconds(0))) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0 && !exit_code_) {
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
}

bool ServerProcess::WaitReady(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const std::unique_ptr<httplib::Client> client = HttpClient();
  client->set_connection_timeout(std::chrono::milliseconds(200));
  while (std::chrono::steady_clock::now() < deadline) {
    if (WaitExit(std::chrono::milliseconds(0))) return false;
    if (const auto response = client->Get("/v2/health/ready");
        response && response->status == 200) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

void ServerProcess::Signal(int signal_number) const {
  if (pid_ > 0 && !exit_code_) kill(pid_, signal_number);
}

std::optional<int> ServerProcess::WaitExit(std::chrono::milliseconds timeout) {
  if (exit_code_ || pid_ <= 0) return exit_code_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exit_code_ = DecodeWaitStatus(status);
      return exit_code_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::string ServerProcess::Log() const { return ReadAll(log_path_); }

std::unique_ptr<httplib::Client> ServerProcess::HttpClient() const {
  const std::string address = "127.0.0.1:" + std::to_string(http_port_);
  if (tls_.ca_cert.empty()) return std::make_unique<httplib::Client>("http://" + address);
  auto client =
      std::make_unique<httplib::Client>("https://" + address, tls_.client_cert, tls_.client_key);
  client->set_ca_cert_path(tls_.ca_cert.c_str());
  client->enable_server_certificate_verification(true);
  return client;
}

std::string ServerProcess::Metrics() const {
  const auto response = HttpClient()->Get("/metrics");
  return response && response->status == 200 ? response->body : "";
}

bool ServerProcess::WaitForMetric(const std::string& series, double value,
                                  std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (MetricValue(Metrics(), series).value_or(-1) >= value) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

std::string ScrapeMetrics(int http_port) {
  httplib::Client client("127.0.0.1", http_port);
  const auto response = client.Get("/metrics");
  return response && response->status == 200 ? response->body : "";
}

std::optional<double> MetricValue(const std::string& metrics_text, const std::string& series) {
  std::istringstream lines(metrics_text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  return std::nullopt;
}

}  // namespace tod::server::testing
