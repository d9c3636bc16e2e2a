// The model repository: several bundles served at once by name, chosen per request, reloaded
// bundle by bundle (SIGHUP and the admin calls) while the others keep serving; a broken bundle
// is refused by name. Unit level on ModelHolder, then through tod_server's REST, OIP and gRPC.
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <string>

#include "client/tod_grpc_client.h"
#include "server/core/model_holder.h"
#include "tests/service/server_harness.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::MetricValue;
using testing::ServerProcess;
using testing::TestModel;

// A repository with the fixture's bundle as `a` and `b`, and `broken` (a manifest that is not
// JSON).
std::string MakeRepository() {
  const std::string repository = testing::MakeTempDir("tod_repository");
  for (const char* name : {"a", "b"})
    fs::copy(TestModel(), fs::path(repository) / name, fs::copy_options::recursive);
  fs::create_directories(fs::path(repository) / "broken");
  std::ofstream(fs::path(repository) / "broken" / "manifest.json") << "{ not json";
  return repository;
}

// Rewrites a file of the bundle with the same bytes: the bundle counts as replaced.
void Touch(const fs::path& bundle) {
  const fs::path manifest = bundle / "manifest.json";
  fs::last_write_time(manifest, fs::last_write_time(manifest) + 2s);
}

std::vector<std::string> Names(const ModelHolder& models) {
  std::vector<std::string> names;
  for (const auto& model : models.Models()) names.push_back(model->name());
  return names;
}

TEST(ModelRepositoryTest, LoadsEveryBundleByNameAndRefusesTheBrokenOne) {
  REQUIRE_MODEL();
  const std::string repository = MakeRepository();
  ModelHolder models;
  const Result<RepositoryChanges> loaded = models.LoadRepository(repository);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->loaded, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(loaded->refused.size(), 1u);
  EXPECT_EQ(loaded->refused[0].first, "broken");
  EXPECT_NE(loaded->status().message().find("model 'broken'"), std::string::npos);
  EXPECT_EQ(Names(models), (std::vector<std::string>{"a", "b"}));
  ASSERT_NE(models.Current(), nullptr);
  EXPECT_EQ(models.Current()->name(), "a");  // no "default": the first by name
  EXPECT_EQ(models.Find("b")->name(), "b");
  EXPECT_EQ(models.Find("broken"), nullptr);
  ASSERT_EQ(models.Refused().count("broken"), 1u);
  EXPECT_EQ(models.Refused().at("broken").code(), StatusCode::kDataLoss);

  // Added, replaced, removed: loaded, swapped, unloaded; the unchanged one stays as it is.
  fs::copy(TestModel(), fs::path(repository) / "default", fs::copy_options::recursive);
  Touch(fs::path(repository) / "b");
  const auto a_before = models.Find("a");
  fs::remove_all(fs::path(repository) / "broken");
  const RepositoryChanges reloaded = models.Reload();
  EXPECT_EQ(reloaded.loaded, std::vector<std::string>{"default"});
  EXPECT_EQ(reloaded.swapped, std::vector<std::string>{"b"});
  EXPECT_TRUE(reloaded.refused.empty());
  EXPECT_TRUE(models.Refused().empty());  // removed from the directory: forgotten
  EXPECT_EQ(models.Find("a"), a_before);
  EXPECT_EQ(models.Find("b")->generation, 2);
  EXPECT_EQ(models.Current()->name(), "default");  // "default" is the default when there

  fs::remove_all(fs::path(repository) / "default");
  EXPECT_EQ(models.Reload().unloaded, std::vector<std::string>{"default"});
  EXPECT_EQ(models.Current()->name(), "a");
  EXPECT_TRUE(models.UnloadModel("a").ok());
  EXPECT_EQ(models.Find("a"), nullptr);
  EXPECT_EQ(models.UnloadModel("a").code(), StatusCode::kNotFound);
  EXPECT_TRUE(models.LoadModel("a").ok());
  EXPECT_EQ(models.Find("a")->generation, 2);
  EXPECT_EQ(models.LoadModel("../a").code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(models.LoadModel("missing").code(), StatusCode::kNotFound);
  fs::remove_all(repository);
}

TEST(ModelRepositoryTest, RefusesAMissingDefaultAndARepositoryWhereNothingLoads) {
  REQUIRE_MODEL();
  const std::string repository = MakeRepository();
  ModelHolder models;
  EXPECT_EQ(models.LoadRepository(repository, "zzz").status().code(), StatusCode::kNotFound);
  const Result<RepositoryChanges> with_default = models.LoadRepository(repository, "b");
  ASSERT_TRUE(with_default.ok());
  EXPECT_EQ(models.Current()->name(), "b");
  EXPECT_TRUE(models.UnloadModel("b").ok());
  EXPECT_EQ(models.Current(), nullptr);  // the configured default is not chosen anew
  EXPECT_FALSE(models.empty());

  const std::string empty = testing::MakeTempDir("tod_repository_empty");
  EXPECT_EQ(models.LoadRepository(empty).status().code(), StatusCode::kFailedPrecondition);
  EXPECT_FALSE(ModelHolder().LoadRepository(empty + "/missing").ok());
  ModelHolder single;
  EXPECT_EQ(single.LoadModel("a").code(), StatusCode::kFailedPrecondition);  // not a repository
  fs::remove_all(repository);
  fs::remove_all(empty);
}

httplib::Result PostPng(httplib::Client& client, const std::string& path) {
  return client.Post(path.c_str(), testing::RoadPng(), "image/png");
}

TEST(ModelRepositoryServiceTest, ServesEveryBundleByNameAndReloadsThemOneByOne) {
  REQUIRE_MODEL();
  const std::string repository = MakeRepository();
  const std::string admin_tokens = repository + "/../admin_tokens_" + std::to_string(::getpid());
  std::ofstream(admin_tokens) << "admin-token-0123456789abcdef\n";
  auto server = ServerProcess::Start(
      "", {"--model-repository", repository, "--admin-token-file", admin_tokens, "--workers", "1"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  auto http = server->HttpClient();
  http->set_read_timeout(60s);

  // Each request names its model (the default, "a", when omitted) on every API.
  for (const std::string path : {"/v1/detect", "/v1/detect?model=a", "/v1/detect?model=b"}) {
    const auto result = PostPng(*http, path);
    ASSERT_TRUE(result) << path;
    EXPECT_EQ(result->status, 200) << path << ": " << result->body;
  }
  const auto unknown = PostPng(*http, "/v1/detect?model=broken");
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->status, 404) << unknown->body;
  const auto info = http->Get("/v1/model?model=b");
  ASSERT_TRUE(info);
  EXPECT_EQ(nlohmann::json::parse(info->body)["name"], "b");
  EXPECT_EQ(http->Get("/v2/models/b/ready")->status, 200);
  EXPECT_EQ(http->Get("/v2/models/broken/ready")->status, 404);

  client::TodGrpcClient grpc(server->grpc_address());
  tod::v1::DetectRequest request;
  request.set_image(testing::RoadPng());
  request.set_model("b");
  tod::v1::DetectResponse response;
  EXPECT_TRUE(grpc.Detect(request, &response).ok());
  request.set_model("nope");
  EXPECT_EQ(grpc.Detect(request, &response).error_code(), grpc::StatusCode::NOT_FOUND);
  const std::string metrics = server->Metrics();
  EXPECT_GE(MetricValue(metrics, "tod_model_frames_total{model=\"b\"}").value_or(0), 2);
  EXPECT_NE(metrics.find("tod_model_info{generation=\"1\",name=\"a\""), std::string::npos);
  EXPECT_NE(metrics.find("tod_model_info{generation=\"1\",name=\"b\""), std::string::npos);

  // SIGHUP under load on a: b removed (unloaded), c added (loaded), a untouched; every request
  // to a is answered 200 throughout (tod_load, two senders over gRPC, for 4 s).
  const std::string frames = testing::MakeTempDir("tod_repository_frames");
  std::ofstream(frames + "/road.png", std::ios::binary) << testing::RoadPng();
  const std::string report = frames + "/load.json";
  auto load = std::async(std::launch::async, [&] {
    return testing::RunCommand({testing::BinaryPath("tod_load"), "--addr", server->grpc_address(),
                                "--images", frames, "--model", "a", "--concurrency", "2",
                                "--duration", "4", "--warmup", "0", "--json", report});
  });
  ASSERT_TRUE(server->WaitForMetric("tod_model_frames_total{model=\"a\"}", 3)) << server->Log();
  fs::remove_all(fs::path(repository) / "b");
  fs::copy(TestModel(), fs::path(repository) / "c", fs::copy_options::recursive);
  server->Signal(SIGHUP);
  const testing::ProcessResult loaded = load.get();
  ASSERT_EQ(loaded.exit_code, 0) << loaded.output;
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(report));
  EXPECT_GT(stats["requests"].get<int>(), 0);
  EXPECT_EQ(stats["succeeded"], stats["requests"]) << stats.dump();
  ASSERT_TRUE(server->WaitForMetric("tod_model_reloads_total{result=\"success\"}", 1));
  EXPECT_EQ(http->Get("/v2/models/c/ready")->status, 200) << server->Log();
  EXPECT_EQ(http->Get("/v2/models/b/ready")->status, 404);
  fs::remove_all(frames);

  // The admin calls: only with an admin token (the API's token is another).
  const httplib::Headers admin = {{"Authorization", "Bearer admin-token-0123456789abcdef"}};
  EXPECT_EQ(http->Post("/v2/repository/models/c/unload", "", "application/json")->status, 401);
  EXPECT_EQ(http->Post("/v2/repository/models/c/unload", admin, "", "application/json")->status,
            200);
  EXPECT_EQ(http->Get("/v2/models/c/ready")->status, 404);
  EXPECT_EQ(http->Post("/v2/repository/models/c/load", admin, "", "application/json")->status, 200);
  EXPECT_EQ(http->Get("/v2/models/c/ready")->status, 200);
  const auto refused = http->Post("/v2/repository/models/zz/load", admin, "", "application/json");
  EXPECT_EQ(refused->status, 404) << refused->body;
  const auto index = http->Post("/v2/repository/index", admin, "", "application/json");
  ASSERT_EQ(index->status, 200);
  const nlohmann::json entries = nlohmann::json::parse(index->body);
  ASSERT_EQ(entries.size(), 3u) << index->body;  // a and c serving, broken refused
  EXPECT_EQ(entries[0]["name"], "a");
  EXPECT_EQ(entries[0]["state"], "READY");
  EXPECT_EQ(entries[1]["name"], "c");
  EXPECT_EQ(entries[2]["name"], "broken");
  EXPECT_EQ(entries[2]["state"], "UNAVAILABLE");
  EXPECT_NE(entries[2]["reason"].get<std::string>().find("not valid JSON"), std::string::npos);
  server->Signal(SIGTERM);
  EXPECT_EQ(server->WaitExit(30s), 0);
  const std::string log = server->Log();  // whole once the server has exited
  EXPECT_NE(log.find("model refused"), std::string::npos) << log;
  EXPECT_NE(log.find("name=broken"), std::string::npos) << "the refusal names the bundle";
  EXPECT_NE(log.find("model unloaded name=b"), std::string::npos) << log;
  fs::remove_all(repository);
  fs::remove(admin_tokens);
}

TEST(ModelRepositoryServiceTest, RepositoryCallsAreOffWithoutAdminTokens) {
  REQUIRE_MODEL();
  auto server = ServerProcess::Start(TestModel(), {"--workers", "1"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  auto http = server->HttpClient();
  const auto result = http->Post("/v2/repository/models/model/unload", "", "application/json");
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, 403) << result->body;
  EXPECT_EQ(http->Get("/v2/models/model/ready")->status, 200);
}

}  // namespace
}  // namespace tod::server
