#include "tests/service/test_pki.h"

#include <fstream>
#include <vector>

#include "tests/service/server_harness.h"

namespace tod::server::testing {
namespace {

const char kOpenSsl[] = "/usr/bin/openssl";

// P-256 keys: quick to make, and every TLS stack here speaks them.
const std::vector<std::string> kNewKey = {"-newkey", "ec", "-pkeyopt",
                                          "ec_paramgen_curve:prime256v1", "-nodes"};

bool Run(const std::vector<std::string>& args, std::string* log) {
  // Built by appending rather than by inserting a literal at the front: GCC 12 with LTO reports
  // a false -Wstringop-overread for the insert.
  std::vector<std::string> argv;
  argv.reserve(args.size() + 1);
  argv.emplace_back(kOpenSsl);
  argv.insert(argv.end(), args.begin(), args.end());
  const ProcessResult result = RunCommand(argv);
  *log += result.output;
  return result.exit_code == 0;
}

bool MakeCa(const std::string& dir, const std::string& name, std::string* log) {
  std::vector<std::string> argv = {"req", "-x509"};
  argv.insert(argv.end(), kNewKey.begin(), kNewKey.end());
  argv.insert(argv.end(), {"-keyout", dir + "/" + name + ".key", "-out", dir + "/" + name + ".crt",
                           "-days", "2", "-subj", "/CN=" + name});
  return Run(argv, log);
}

// A key and a certificate for `name` signed by the CA `ca`, with the extensions in `extensions`.
bool MakeLeaf(const std::string& dir, const std::string& ca, const std::string& name,
              const std::string& extensions, std::string* log) {
  const std::string base = dir + "/" + name;
  std::ofstream(base + ".ext") << extensions << "\n";
  std::vector<std::string> request = {"req"};
  request.insert(request.end(), kNewKey.begin(), kNewKey.end());
  request.insert(request.end(),
                 {"-keyout", base + ".key", "-out", base + ".csr", "-subj", "/CN=" + name});
  return Run(request, log) &&
         Run({"x509", "-req", "-in", base + ".csr", "-CA", dir + "/" + ca + ".crt", "-CAkey",
              dir + "/" + ca + ".key", "-CAcreateserial", "-out", base + ".crt", "-days", "2",
              "-extfile", base + ".ext"},
             log);
}

}  // namespace

std::optional<TestPki> MakeTestPki(std::string* log) {
  TestPki pki;
  pki.dir = MakeTempDir("tod_pki");
  const std::string& dir = pki.dir;
  const bool made =
      MakeCa(dir, "ca", log) && MakeCa(dir, "stranger_ca", log) &&
      MakeLeaf(dir, "ca", "server",
               "subjectAltName=DNS:localhost,IP:127.0.0.1\nextendedKeyUsage=serverAuth", log) &&
      MakeLeaf(dir, "ca", "client", "extendedKeyUsage=clientAuth", log) &&
      MakeLeaf(dir, "stranger_ca", "stranger", "extendedKeyUsage=clientAuth", log);
  if (!made) return std::nullopt;
  pki.ca_cert = dir + "/ca.crt";
  pki.server_cert = dir + "/server.crt";
  pki.server_key = dir + "/server.key";
  pki.client_cert = dir + "/client.crt";
  pki.client_key = dir + "/client.key";
  pki.stranger_cert = dir + "/stranger.crt";
  pki.stranger_key = dir + "/stranger.key";
  return pki;
}

}  // namespace tod::server::testing
