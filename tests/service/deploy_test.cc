// What can be checked of the deployment without a Docker engine or a cluster: the Kustomize
// manifests' structure, the KServe InferenceService (its arguments start a real server), the
// Dockerfile's contract, and that the runtime package list covers every shared library
// tod_server loads.
#include <gtest/gtest.h>
#include <httplib.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "tests/service/mini_yaml.h"
#include "tests/service/server_harness.h"
#include "tests/test_env.h"

namespace tod::server {
namespace {

namespace fs = std::filesystem;
using testing::ParseYamlDocuments;
using testing::YamlNode;

std::string SourceDir() { return tod::testing_env::SourceDir(); }

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Runs a shell command; stdout, and whether it exited 0.
std::pair<std::string, bool> Shell(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {"", false};
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) output.append(buffer, n);
  const int status = pclose(pipe);
  return {output, status == 0};
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// Every key/value of `subset` (a map of labels) is in `labels`.
bool LabelsContain(const YamlNode* labels, const YamlNode* subset) {
  if (labels == nullptr || subset == nullptr || subset->entries.empty()) return false;
  for (const auto& [key, value] : subset->entries) {
    const YamlNode* label = labels->Get(key);  // label keys contain dots: no Path() here
    if (label == nullptr || label->scalar != value.scalar) return false;
  }
  return true;
}

const YamlNode* FindKind(const std::vector<YamlNode>& docs, const std::string& kind,
                         const std::string& name = "") {
  for (const YamlNode& doc : docs) {
    if (doc.Str("kind") == kind && (name.empty() || doc.Str("metadata.name") == name)) return &doc;
  }
  return nullptr;
}

TEST(MiniYamlTest, ParsesTheKustomizeStyleSubset) {
  const auto docs = ParseYamlDocuments(
      "a: 1\n"
      "list:\n"
      "- name: x   # comment\n"
      "  port: \"8001\"\n"
      "- plain\n"
      "nested:\n"
      "  flow: [\"/bin/sleep\", 5]\n"
      "  empty: {}\n"
      "---\n"
      "b: 'two'\n");
  ASSERT_TRUE(docs.ok()) << docs.status().message();
  ASSERT_EQ(docs->size(), 2u);
  const YamlNode& first = (*docs)[0];
  EXPECT_EQ(first.Str("a"), "1");
  const YamlNode* list = first.Get("list");
  ASSERT_NE(list, nullptr);
  ASSERT_EQ(list->items.size(), 2u);
  EXPECT_EQ(list->items[0].Str("name"), "x");
  EXPECT_EQ(list->items[0].Str("port"), "8001");
  EXPECT_EQ(list->items[1].scalar, "plain");
  ASSERT_EQ(first.Path("nested.flow")->items.size(), 2u);
  EXPECT_EQ(first.Path("nested.flow")->items[0].scalar, "/bin/sleep");
  EXPECT_EQ((*docs)[1].Str("b"), "two");
  EXPECT_FALSE(ParseYamlDocuments("a: 1\n   b: 2\n").ok());
}

TEST(DeployTest, KustomizationListsParseableResources) {
  const std::string dir = SourceDir() + "/deploy/k8s";
  ASSERT_TRUE(fs::exists(dir + "/kustomization.yaml")) << dir;
  const auto kustomization = ParseYamlDocuments(ReadText(dir + "/kustomization.yaml"));
  ASSERT_TRUE(kustomization.ok()) << kustomization.status().message();
  const YamlNode* resources = (*kustomization)[0].Get("resources");
  ASSERT_NE(resources, nullptr);
  EXPECT_GE(resources->items.size(), 5u);
  for (const YamlNode& resource : resources->items) {
    const std::string path = dir + "/" + resource.scalar;
    ASSERT_TRUE(fs::exists(path)) << path;
    const auto docs = ParseYamlDocuments(ReadText(path));
    ASSERT_TRUE(docs.ok()) << path << ": " << docs.status().message();
    EXPECT_FALSE((*docs)[0].Str("kind").empty()) << path;
  }
}

TEST(DeployTest, RenderedManifestsAreConsistent) {
  if (!Shell("command -v kubectl >/dev/null 2>&1").second) {
    GTEST_SKIP() << "kubectl not installed; rendered-manifest checks skipped";
  }
  const auto [rendered, ok] = Shell("kubectl kustomize " + SourceDir() + "/deploy/k8s 2>&1");
  ASSERT_TRUE(ok) << rendered;
  const auto parsed = ParseYamlDocuments(rendered);
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  const std::vector<YamlNode>& docs = *parsed;

  const YamlNode* deployment = FindKind(docs, "Deployment");
  ASSERT_NE(deployment, nullptr);
  const YamlNode* pod_labels = deployment->Path("spec.template.metadata.labels");
  EXPECT_TRUE(LabelsContain(pod_labels, deployment->Path("spec.selector.matchLabels")));

  const YamlNode* pod = deployment->Path("spec.template.spec");
  ASSERT_NE(pod, nullptr);
  const YamlNode& container = pod->Get("containers")->items.at(0);
  std::set<std::string> port_names;
  std::set<std::string> port_numbers;
  for (const YamlNode& port : container.Get("ports")->items) {
    port_names.insert(port.Str("name"));
    port_numbers.insert(port.Str("containerPort"));
  }
  auto is_container_port = [&](const std::string& port) {
    return port_names.count(port) > 0 || port_numbers.count(port) > 0;
  };
  // Probes: readiness, liveness, a startup probe; all on ports the container exposes. With TLS
  // on, kubelet's gRPC probe cannot connect: every probe is then HTTPS.
  const bool tls = !container.Str("readinessProbe.httpGet.scheme").empty() ||
                   container.Path("readinessProbe.grpc") == nullptr;
  if (tls) {
    EXPECT_EQ(container.Str("readinessProbe.httpGet.scheme"), "HTTPS");
    EXPECT_TRUE(is_container_port(container.Str("readinessProbe.httpGet.port")));
    EXPECT_EQ(container.Str("livenessProbe.httpGet.scheme"), "HTTPS");
    EXPECT_EQ(container.Str("startupProbe.httpGet.scheme"), "HTTPS");
  } else {
    EXPECT_TRUE(port_numbers.count(container.Str("readinessProbe.grpc.port")))
        << "gRPC readiness probe port must be a container port number";
  }
  EXPECT_TRUE(is_container_port(container.Str("livenessProbe.httpGet.port")));
  EXPECT_EQ(container.Str("livenessProbe.httpGet.path"), "/v2/health/live");
  const std::string startup_port =
      container.Str("startupProbe.httpGet.port", container.Str("startupProbe.grpc.port"));
  EXPECT_TRUE(is_container_port(startup_port));

  EXPECT_FALSE(container.Str("resources.requests.cpu").empty());
  EXPECT_FALSE(container.Str("resources.limits.cpu").empty());
  EXPECT_EQ(container.Str("securityContext.readOnlyRootFilesystem"), "true");
  EXPECT_EQ(pod->Str("securityContext.runAsNonRoot"), "true");
  ASSERT_NE(container.Path("lifecycle.preStop"), nullptr);

  // The grace period must cover the preStop pause plus the server's drain deadline.
  int drain_s = 20;  // tod_server's default
  for (const YamlNode& arg : container.Get("args")->items) {
    std::smatch match;
    if (std::regex_match(arg.scalar, match, std::regex("--drain-timeout=(\\d+)"))) {
      drain_s = std::stoi(match[1]);
    }
  }
  int pre_stop_s = 0;
  if (const YamlNode* command = container.Path("lifecycle.preStop.exec.command")) {
    if (command->items.size() == 2 && command->items[0].scalar == "/bin/sleep") {
      pre_stop_s = std::stoi(command->items[1].scalar);
    }
  }
  EXPECT_GT(std::stoi(pod->Str("terminationGracePeriodSeconds", "30")), drain_s + pre_stop_s);

  // Services: one headless for gRPC client-side balancing, one normal for HTTP.
  int headless = 0, normal = 0;
  for (const YamlNode& doc : docs) {
    if (doc.Str("kind") != "Service") continue;
    EXPECT_TRUE(LabelsContain(pod_labels, doc.Path("spec.selector"))) << doc.Str("metadata.name");
    for (const YamlNode& port : doc.Path("spec.ports")->items) {
      EXPECT_TRUE(is_container_port(port.Str("targetPort", port.Str("port"))))
          << doc.Str("metadata.name") << " targets a port the container does not expose";
    }
    (doc.Str("spec.clusterIP") == "None" ? headless : normal) += 1;
  }
  EXPECT_EQ(headless, 1);
  EXPECT_GE(normal, 1);

  const YamlNode* hpa = FindKind(docs, "HorizontalPodAutoscaler");
  ASSERT_NE(hpa, nullptr);
  EXPECT_EQ(hpa->Str("spec.scaleTargetRef.kind"), "Deployment");
  EXPECT_EQ(hpa->Str("spec.scaleTargetRef.name"), deployment->Str("metadata.name"));
  const YamlNode* pdb = FindKind(docs, "PodDisruptionBudget");
  ASSERT_NE(pdb, nullptr);
  EXPECT_TRUE(LabelsContain(pod_labels, pdb->Path("spec.selector.matchLabels")));
}

// TLS files and tokens come from Secrets mounted read-only where the server's flags point, and
// the probes (which cannot present tokens or speak gRPC over TLS) use HTTPS on open paths.
TEST(DeployTest, DeploymentMountsTlsAndTokensFromSecrets) {
  const auto docs = ParseYamlDocuments(ReadText(SourceDir() + "/deploy/k8s/deployment.yaml"));
  ASSERT_TRUE(docs.ok()) << docs.status().message();
  const YamlNode* pod = (*docs)[0].Path("spec.template.spec");
  ASSERT_NE(pod, nullptr);
  const YamlNode& container = pod->Get("containers")->items.at(0);
  std::map<std::string, std::string> flags;  // --name=value
  for (const YamlNode& arg : container.Get("args")->items) {
    const size_t equals = arg.scalar.find('=');
    if (equals != std::string::npos)
      flags[arg.scalar.substr(0, equals)] = arg.scalar.substr(equals + 1);
  }
  std::map<std::string, std::string> secret_of_volume;
  for (const YamlNode& volume : pod->Get("volumes")->items) {
    if (!volume.Str("secret.secretName").empty()) {
      secret_of_volume[volume.Str("name")] = volume.Str("secret.secretName");
    }
  }
  // Each file flag points into a read-only mount of a Secret volume.
  auto secret_for = [&](const std::string& path) -> std::string {
    for (const YamlNode& mount : container.Get("volumeMounts")->items) {
      const std::string dir = mount.Str("mountPath") + "/";
      if (path.rfind(dir, 0) != 0) continue;
      EXPECT_EQ(mount.Str("readOnly"), "true") << dir;
      const auto secret = secret_of_volume.find(mount.Str("name"));
      return secret == secret_of_volume.end() ? "" : secret->second;
    }
    return "";
  };
  for (const char* flag : {"--tls-cert", "--tls-key", "--auth-token-file"}) {
    ASSERT_TRUE(flags.count(flag)) << flag << " missing from the container args";
    EXPECT_FALSE(secret_for(flags[flag]).empty()) << flag << " is not on a mounted Secret";
  }
  EXPECT_EQ(secret_for(flags["--tls-cert"]), secret_for(flags["--tls-key"]));
  EXPECT_NE(secret_for(flags["--tls-cert"]), secret_for(flags["--auth-token-file"]));
  // The non-root user can read the Secret files.
  EXPECT_EQ(pod->Str("securityContext.fsGroup"), pod->Str("securityContext.runAsGroup"));
  // Probes stay on the open paths, over HTTPS.
  for (const char* probe : {"readinessProbe", "livenessProbe", "startupProbe"}) {
    const std::string prefix = std::string(probe) + ".httpGet.";
    EXPECT_EQ(container.Str(prefix + "scheme"), "HTTPS") << probe;
    EXPECT_EQ(container.Str(prefix + "path").rfind("/v2/health/", 0), 0u) << probe;
  }
}

// KServe sends a custom predictor's traffic to kserve-container on port 8080 and probes it; the
// REST listener must be there, the probes on the open v2 health paths, the model the image's.
// The container's arguments must also start the server: they run here, with the test model and
// free ports in place of the image's model and the fixed ports.
TEST(DeployTest, KserveInferenceServiceRunsTheServerAsAV2Predictor) {
  const auto docs =
      ParseYamlDocuments(ReadText(SourceDir() + "/deploy/k8s/kserve/inferenceservice.yaml"));
  ASSERT_TRUE(docs.ok()) << docs.status().message();
  const YamlNode& service = (*docs)[0];
  EXPECT_EQ(service.Str("apiVersion"), "serving.kserve.io/v1beta1");
  EXPECT_EQ(service.Str("kind"), "InferenceService");
  const YamlNode* containers = service.Path("spec.predictor.containers");
  ASSERT_NE(containers, nullptr);
  ASSERT_EQ(containers->items.size(), 1u);
  const YamlNode& container = containers->items[0];
  EXPECT_EQ(container.Str("name"), "kserve-container");
  ASSERT_EQ(container.Get("ports")->items.size(), 1u);
  EXPECT_EQ(container.Get("ports")->items[0].Str("containerPort"), "8080");
  for (const char* probe : {"readinessProbe", "livenessProbe"}) {
    const std::string prefix = std::string(probe) + ".httpGet.";
    EXPECT_EQ(container.Str(prefix + "port"), "8080") << probe;
    EXPECT_EQ(container.Str(prefix + "path").rfind("/v2/health/", 0), 0u) << probe;
  }
  std::map<std::string, std::string> flags;
  std::vector<std::string> other_args;
  for (const YamlNode& arg : container.Get("args")->items) {
    const size_t equals = arg.scalar.find('=');
    const std::string name = arg.scalar.substr(0, equals);
    if (name == "--model" || name == "--http-port" || name == "--grpc-port") {
      flags[name] = arg.scalar.substr(equals + 1);
    } else {
      other_args.push_back(arg.scalar);
    }
  }
  EXPECT_EQ(flags["--http-port"], "8080");
  EXPECT_EQ(flags["--model"], "/opt/tod/models/default") << "the bundle the Dockerfile copies";

  REQUIRE_MODEL();
  auto server = testing::ServerProcess::Start(testing::TestModel(), other_args);
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const auto model = server->HttpClient()->Get(
      "/v2/models/" + fs::path(testing::TestModel()).filename().string() + "/ready");
  ASSERT_TRUE(model);
  EXPECT_EQ(model->status, 200) << model->body;
}

TEST(DeployTest, DockerfileFollowsTheContract) {
  const std::string dockerfile = ReadText(SourceDir() + "/Dockerfile");
  ASSERT_FALSE(dockerfile.empty());
  EXPECT_NE(dockerfile.find("FROM debian:12"), std::string::npos);
  EXPECT_NE(dockerfile.find("deploy/deps.sh build"), std::string::npos);
  EXPECT_NE(dockerfile.find("deps.sh runtime"), std::string::npos);
  EXPECT_NE(dockerfile.find("ctest"), std::string::npos) << "the build stage runs the tests";
  EXPECT_NE(dockerfile.find("ENTRYPOINT [\"/usr/bin/tini\""), std::string::npos);
  EXPECT_NE(dockerfile.find("HEALTHCHECK"), std::string::npos);
  EXPECT_NE(dockerfile.find("tod_client\", \"health\""), std::string::npos);
  EXPECT_NE(dockerfile.find("EXPOSE 8001 8000"), std::string::npos);
  EXPECT_NE(dockerfile.find("/opt/tod/models/default"), std::string::npos);
  // The last USER is not root.
  const size_t user = dockerfile.rfind("\nUSER ");
  ASSERT_NE(user, std::string::npos);
  const std::string who = dockerfile.substr(user + 6, dockerfile.find('\n', user + 1) - user - 6);
  EXPECT_NE(who, "root");
  EXPECT_NE(who.rfind("0", 0), 0u);
  // No package is installed behind deps.sh's back.
  EXPECT_EQ(dockerfile.find("apt-get install"), std::string::npos);
}

// Every shared library tod_server loads belongs to a package that is in the runtime list or in
// its dependency closure (Depends + Pre-Depends, following Provides), so the runtime image built
// from `deploy/deps.sh runtime` can start the server.
TEST(DeployTest, RuntimePackagesCoverEverySharedLibraryOfTheServer) {
  if (!Shell("command -v dpkg-query >/dev/null 2>&1").second) GTEST_SKIP() << "not Debian";
  const std::string server = tod::testing_env::BinDir() + "/tod_server";
  ASSERT_TRUE(fs::exists(server));

  const auto [listed, listed_ok] = Shell("bash " + SourceDir() + "/deploy/deps.sh --print runtime");
  ASSERT_TRUE(listed_ok);
  const std::vector<std::string> runtime = Lines(listed);
  ASSERT_FALSE(runtime.empty());

  // Installed packages: dependencies and what each provides.
  const auto [table, table_ok] =
      Shell("dpkg-query -W -f='${Package}\\t${Depends}, ${Pre-Depends}\\t${Provides}\\n'");
  ASSERT_TRUE(table_ok);
  std::map<std::string, std::vector<std::string>> depends;
  std::map<std::string, std::vector<std::string>> providers;  // virtual -> real packages
  const std::regex name_pattern("([a-z0-9][a-z0-9+.-]+)(:[a-z0-9]+)?");
  auto names = [&](const std::string& field) {
    std::vector<std::string> out;
    std::stringstream parts(field);
    std::string part;
    while (std::getline(parts, part, ',')) {
      std::stringstream alternatives(part);
      std::string alternative;
      while (std::getline(alternatives, alternative, '|')) {
        const size_t start = alternative.find_first_not_of(' ');
        if (start == std::string::npos) continue;
        const std::string trimmed = alternative.substr(start);
        std::smatch match;
        if (std::regex_search(trimmed, match, name_pattern) && match.position(0) == 0) {
          out.push_back(match[1]);
        }
      }
    }
    return out;
  };
  for (const std::string& line : Lines(table)) {
    std::stringstream fields(line);
    std::string package, deps, provides;
    std::getline(fields, package, '\t');
    std::getline(fields, deps, '\t');
    std::getline(fields, provides, '\t');
    depends[package] = names(deps);
    for (const std::string& virtual_name : names(provides))
      providers[virtual_name].push_back(package);
  }
  std::set<std::string> closure;
  std::vector<std::string> pending = runtime;
  while (!pending.empty()) {
    const std::string package = pending.back();
    pending.pop_back();
    if (!closure.insert(package).second) continue;
    for (const std::string& dep : depends[package]) pending.push_back(dep);
    for (const std::string& real : providers[package]) pending.push_back(real);
  }

  // The libraries the dynamic loader resolves for tod_server, and their owning packages.
  const auto [ldd, ldd_ok] = Shell("ldd " + server);
  ASSERT_TRUE(ldd_ok) << ldd;
  const std::regex library_pattern(R"((/[^ ]+\.so[^ ]*) \(0x)");
  std::vector<std::vector<std::string>> candidates;  // per library: paths dpkg may know it by
  std::string all_candidates;
  for (const std::string& line : Lines(ldd)) {
    std::smatch match;
    if (!std::regex_search(line, match, library_pattern)) continue;
    const std::string path = match[1];
    // usrmerge: dpkg may know the file under /lib or /usr/lib, or only by its real path.
    std::vector<std::string> names = {path, fs::weakly_canonical(path).string(),
                                      path.rfind("/usr/", 0) == 0 ? path.substr(4) : "/usr" + path};
    for (const std::string& name : names) all_candidates += " '" + name + "'";
    candidates.push_back(std::move(names));
  }
  const int libraries = static_cast<int>(candidates.size());
  // One dpkg -S for all paths ("pkg[:arch][, pkg2]: /path" per found path; unknown ones are
  // reported on stderr and make the exit code non-zero, which is expected here).
  const std::string owners_text = Shell("dpkg -S" + all_candidates + " 2>/dev/null").first;
  std::map<std::string, std::string> owner_of;
  for (const std::string& line : Lines(owners_text)) {
    const size_t separator = line.rfind(": /");
    if (separator == std::string::npos || line.rfind("diversion", 0) == 0) continue;
    owner_of[line.substr(separator + 2)] = line.substr(0, line.find_first_of(":,"));
  }
  std::vector<std::string> missing;
  for (const std::vector<std::string>& names : candidates) {
    std::string owner;
    for (const std::string& name : names) {
      if (const auto it = owner_of.find(name); it != owner_of.end()) {
        owner = it->second;
        break;
      }
    }
    if (owner.empty()) {
      missing.push_back(names[0] + " (no package owns it)");
    } else if (closure.count(owner) == 0) {
      missing.push_back(names[0] + " (" + owner + ")");
    }
  }
  EXPECT_GT(libraries, 10);
  std::string report;
  for (const std::string& item : missing) report += "\n  " + item;
  EXPECT_TRUE(missing.empty()) << "add to RUNTIME_PACKAGES in deploy/deps.sh:" << report;
}

}  // namespace
}  // namespace tod::server
