// Configuration precedence (file < environment < flags) and validation messages.
#include "server/config.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

namespace tod::server {
namespace {

EnvLookup FakeEnv(std::map<std::string, std::string> values) {
  auto shared = std::make_shared<std::map<std::string, std::string>>(std::move(values));
  return [shared](const char* name) -> const char* {
    const auto it = shared->find(name);
    return it == shared->end() ? nullptr : it->second.c_str();
  };
}

std::string WriteTempFile(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(ConfigTest, DefaultsNeedOnlyAModel) {
  const Result<ServerConfig> config = ResolveServerConfig({{"model", "/m"}}, FakeEnv({}));
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->model_dir, "/m");
  EXPECT_EQ(config->grpc_port, 8001);
  EXPECT_EQ(config->http_port, 8000);
  EXPECT_GE(config->workers, 1);  // 0 resolved to the core count
  EXPECT_EQ(config->queue, 64);
}

TEST(ConfigTest, FlagsBeatEnvironmentBeatsFile) {
  const std::string file =
      WriteTempFile("tod_config_test.json",
                    R"({"model": "/from/file", "grpc_port": 9001, "http_port": 9000, "queue": 3,
          "log_format": "json"})");
  const Result<ServerConfig> config = ResolveServerConfig(
      {{"config", file}, {"grpc_port", "7001"}},
      FakeEnv({{"TOD_GRPC_PORT", "8101"}, {"TOD_HTTP_PORT", "8100"}, {"TOD_WORKERS", "3"}}));
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->model_dir, "/from/file");  // file only
  EXPECT_EQ(config->queue, 3);                 // file only
  EXPECT_EQ(config->log_format, "json");       // file only
  EXPECT_EQ(config->http_port, 8100);          // env beats file
  EXPECT_EQ(config->workers, 3);               // env only
  EXPECT_EQ(config->grpc_port, 7001);          // flag beats env and file
  std::remove(file.c_str());
}

TEST(ConfigTest, ConfigFileFromEnvironment) {
  const std::string file = WriteTempFile("tod_config_env.json", R"({"model": "/env/file"})");
  const Result<ServerConfig> config = ResolveServerConfig({}, FakeEnv({{"TOD_CONFIG", file}}));
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->model_dir, "/env/file");
  std::remove(file.c_str());
}

TEST(ConfigTest, ErrorsNameTheSourceAndTheSetting) {
  const Status no_model = ResolveServerConfig({}, FakeEnv({})).status();
  EXPECT_NE(no_model.message().find("--model"), std::string::npos) << no_model.message();

  const Status bad_env =
      ResolveServerConfig({{"model", "/m"}}, FakeEnv({{"TOD_QUEUE", "many"}})).status();
  EXPECT_NE(bad_env.message().find("TOD_QUEUE"), std::string::npos) << bad_env.message();

  const std::string file = WriteTempFile("tod_config_bad.json", R"({"modle": "/x"})");
  const Status unknown = ResolveServerConfig({{"config", file}}, FakeEnv({})).status();
  EXPECT_NE(unknown.message().find(file), std::string::npos) << unknown.message();
  EXPECT_NE(unknown.message().find("modle"), std::string::npos) << unknown.message();
  std::remove(file.c_str());

  const std::string broken = WriteTempFile("tod_config_broken.json", "{not json");
  const Status invalid = ResolveServerConfig({{"config", broken}}, FakeEnv({})).status();
  EXPECT_NE(invalid.message().find("invalid JSON"), std::string::npos) << invalid.message();
  std::remove(broken.c_str());

  EXPECT_FALSE(ResolveServerConfig({{"config", "/no/such/file.json"}}, FakeEnv({})).ok());
  EXPECT_FALSE(ResolveServerConfig({{"model", "/m"}, {"grpc_port", "70000"}}, FakeEnv({})).ok());
  EXPECT_FALSE(
      ResolveServerConfig({{"model", "/m"}, {"grpc_port", "9"}, {"http_port", "9"}}, FakeEnv({}))
          .ok());
  EXPECT_FALSE(ResolveServerConfig({{"model", "/m"}, {"log_format", "xml"}}, FakeEnv({})).ok());
  EXPECT_FALSE(
      ResolveServerConfig({{"model", "/m"}, {"max_image_pixels", "1000000000"}}, FakeEnv({})).ok());
}

TEST(ConfigTest, EverySettingHasAFlagAnEnvironmentVariableAndAJsonKey) {
  for (const SettingSpec& spec : SettingSpecs()) {
    EXPECT_EQ(spec.env.rfind("TOD_", 0), 0u) << spec.key;
    ServerConfig config;
    // Each key is accepted by the one parser (a number where a number is expected).
    const bool numeric = spec.key != "model" && spec.key != "host" && spec.key != "log_format" &&
                         spec.key != "log_level";
    EXPECT_TRUE(ApplySetting(spec.key, numeric ? "5" : "text", "test", &config).ok()) << spec.key;
    EXPECT_TRUE(ServerConfigToJson(config).contains(spec.key)) << spec.key;
  }
}

TEST(ConfigTest, HttpLimitsComeFromEverySourceAndAreRangeChecked) {
  const Result<ServerConfig> defaults = ResolveServerConfig({{"model", "/m"}}, FakeEnv({}));
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->max_image_pixels, 4'000'000);
  EXPECT_EQ(defaults->http_max_header_bytes, 16u * 1024);
  EXPECT_EQ(defaults->http_max_connections_per_client, 64);
  EXPECT_EQ(defaults->max_cameras, 1024);
  EXPECT_EQ(defaults->camera_idle_s, 600);

  const std::string file =
      WriteTempFile("tod_config_http.json", R"({"model": "/m", "http_max_connections": 100,
          "http_write_timeout_s": 7})");
  const Result<ServerConfig> config = ResolveServerConfig(
      {{"config", file}, {"http_idle_timeout_s", "5"}},
      FakeEnv({{"TOD_HTTP_REQUEST_TIMEOUT", "2.5"}, {"TOD_HTTP_MAX_HEADER_BYTES", "4096"}}));
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->http_max_connections, 100);     // file
  EXPECT_EQ(config->http_write_timeout_s, 7);       // file
  EXPECT_EQ(config->http_request_timeout_s, 2.5);   // environment
  EXPECT_EQ(config->http_max_header_bytes, 4096u);  // environment
  EXPECT_EQ(config->http_idle_timeout_s, 5);        // flag
  std::remove(file.c_str());

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"http_request_timeout_s", "nan"},
      {"http_request_timeout_s", "0"},
      {"http_idle_timeout_s", "inf"},
      {"http_max_connections", "0"},
      {"http_max_connections_per_client", "600"},  // more than http_max_connections
      {"http_max_header_bytes", "100"},
      {"http_max_buffered_bytes", "1000"},
      {"drain_timeout_s", "1e300"},
      {"http_threads", "1000"},
      {"max_cameras", "0"},
      {"camera_idle_s", "0"},
  };
  for (const auto& [key, value] : bad) {
    const Result<ServerConfig> refused =
        ResolveServerConfig({{"model", "/m"}, {key, value}}, FakeEnv({}));
    ASSERT_FALSE(refused.ok()) << key << "=" << value;
    EXPECT_NE(refused.status().message().find(key), std::string::npos)
        << refused.status().message();
  }
}

}  // namespace
}  // namespace tod::server

namespace tod::server {
namespace {

TEST(ConfigTest, TlsAndTokenFilesComeFromFileEnvironmentAndFlags) {
  const std::string file =
      WriteTempFile("tod_config_tls.json",
                    R"({"model": "/m", "tls_cert": "/file/cert.pem", "tls_key": "/file/key.pem",
          "auth_token_file": "/file/tokens"})");
  const Result<ServerConfig> config = ResolveServerConfig(
      {{"config", file}, {"tls_key", "/flag/key.pem"}},
      FakeEnv({{"TOD_TLS_CLIENT_CA", "/env/ca.pem"}, {"TOD_AUTH_TOKEN_FILE", "/env/tokens"}}));
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->tls_cert, "/file/cert.pem");
  EXPECT_EQ(config->tls_key, "/flag/key.pem");
  EXPECT_EQ(config->tls_client_ca, "/env/ca.pem");
  EXPECT_EQ(config->auth_token_file, "/env/tokens");
  const nlohmann::json json = ServerConfigToJson(*config);
  EXPECT_EQ(json["auth_token_file"], "/env/tokens");
}

TEST(ConfigTest, HalfATlsConfigurationIsRefused) {
  const auto cert_only =
      ResolveServerConfig({{"model", "/m"}, {"tls_cert", "/c.pem"}}, FakeEnv({}));
  ASSERT_FALSE(cert_only.ok());
  EXPECT_NE(cert_only.status().message().find("tls_key"), std::string::npos);
  const auto ca_only =
      ResolveServerConfig({{"model", "/m"}, {"tls_client_ca", "/ca.pem"}}, FakeEnv({}));
  ASSERT_FALSE(ca_only.ok());
  EXPECT_NE(ca_only.status().message().find("tls_client_ca"), std::string::npos);
}

}  // namespace
}  // namespace tod::server
