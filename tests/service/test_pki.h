// A throw-away certificate authority for the TLS tests, made at test time with the openssl
// command: a CA, a server certificate for 127.0.0.1 / localhost, a client certificate it signed,
// and a second, unrelated CA (a client certificate from the wrong CA must be refused).
#pragma once

#include <optional>
#include <string>

namespace tod::server::testing {

struct TestPki {
  std::string dir;
  std::string ca_cert;
  std::string server_cert;
  std::string server_key;
  std::string client_cert;
  std::string client_key;
  std::string stranger_cert;  // client certificate signed by an unrelated CA
  std::string stranger_key;
};

// Makes a fresh PKI in a temp directory; nullopt (with `log` filled) when openssl fails.
std::optional<TestPki> MakeTestPki(std::string* log);

}  // namespace tod::server::testing
