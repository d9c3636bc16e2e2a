// Bearer-token authentication: the tokens come from a file (one a line; blank lines and lines
// starting with '#' are skipped) and are reloaded on SIGHUP. A request is let through when its
// `authorization` header (HTTP) or metadata (gRPC) is "Bearer <token>" for one of them.
//
// Only SHA-256 digests of the tokens are kept, and a presented token is hashed and compared with
// every digest in constant time (CRYPTO_memcmp, no early exit), so neither the comparison nor the
// token lengths leak through timing.
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace tod::server {

// Shortest token accepted from the file: a guessable token is refused at load time.
inline constexpr size_t kMinTokenLength = 16;

class TokenAuthenticator {
 public:
  // Loads `path`; an unreadable file, one without tokens or with a too short token is an error.
  static Result<std::shared_ptr<TokenAuthenticator>> FromFile(const std::string& path);

  // Reads the file again and swaps the tokens in; on error the previous tokens stay.
  Status Reload();

  // nullopt when `authorization` carries a valid token; otherwise why not, for the client.
  std::optional<std::string> Check(std::string_view authorization) const;

  size_t token_count() const;
  const std::string& path() const { return path_; }

 private:
  using Digest = std::array<unsigned char, 32>;
  explicit TokenAuthenticator(std::string path) : path_(std::move(path)) {}
  static Result<std::vector<Digest>> ReadTokens(const std::string& path);

  const std::string path_;
  mutable std::mutex mutex_;  // guards digests_ (a snapshot is taken per check)
  std::shared_ptr<const std::vector<Digest>> digests_;
};

}  // namespace tod::server
