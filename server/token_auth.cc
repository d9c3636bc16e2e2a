#include "server/token_auth.h"

#include <openssl/crypto.h>
#include <openssl/sha.h>

#include <algorithm>
#include <cctype>
#include <fstream>

namespace tod::server {
namespace {

constexpr std::string_view kBearer = "Bearer ";

std::string_view Trim(std::string_view text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string_view::npos) return {};
  const size_t end = text.find_last_not_of(" \t\r\n");
  return text.substr(begin, end - begin + 1);
}

std::array<unsigned char, 32> Sha256(std::string_view text) {
  std::array<unsigned char, 32> digest{};
  SHA256(reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest.data());
  return digest;
}

}  // namespace

Result<std::vector<TokenAuthenticator::Digest>> TokenAuthenticator::ReadTokens(
    const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::NotFound("auth_token_file " + path + ": cannot open");
  std::vector<Digest> digests;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string_view token = Trim(line);
    if (token.empty() || token.front() == '#') continue;
    if (token.size() < kMinTokenLength || token.find_first_of(" \t") != std::string_view::npos) {
      // The line number only: the token itself never goes into a message or a log.
      return Status::InvalidArgument("auth_token_file " + path + ": line " +
                                     std::to_string(number) + " is not a token (at least " +
                                     std::to_string(kMinTokenLength) +
                                     " characters without spaces)");
    }
    digests.push_back(Sha256(token));
  }
  if (digests.empty()) {
    return Status::InvalidArgument("auth_token_file " + path + ": no tokens in the file");
  }
  return digests;
}

Result<std::shared_ptr<TokenAuthenticator>> TokenAuthenticator::FromFile(const std::string& path) {
  std::shared_ptr<TokenAuthenticator> auth(new TokenAuthenticator(path));
  if (Status loaded = auth->Reload(); !loaded.ok()) return loaded;
  return auth;
}

Status TokenAuthenticator::Reload() {
  auto digests = ReadTokens(path_);
  if (!digests.ok()) return digests.status();
  auto fresh = std::make_shared<const std::vector<Digest>>(std::move(*digests));
  std::lock_guard lock(mutex_);
  digests_ = std::move(fresh);
  return Status::Ok();
}

size_t TokenAuthenticator::token_count() const {
  std::lock_guard lock(mutex_);
  return digests_ ? digests_->size() : 0;
}

std::optional<std::string> TokenAuthenticator::Check(std::string_view authorization) const {
  if (authorization.empty()) return "missing authorization: send 'authorization: Bearer <token>'";
  // The scheme is case-insensitive (RFC 7235); the token is compared exactly.
  if (authorization.size() <= kBearer.size() ||
      !std::equal(kBearer.begin(), kBearer.end(), authorization.begin(),
                  [](char a, char b) { return std::tolower(a) == std::tolower(b); })) {
    return "authorization is not a bearer token: send 'authorization: Bearer <token>'";
  }
  const Digest presented = Sha256(Trim(authorization.substr(kBearer.size())));
  std::shared_ptr<const std::vector<Digest>> digests;
  {
    std::lock_guard lock(mutex_);
    digests = digests_;
  }
  int matches = 0;
  for (const Digest& digest : *digests) {  // every digest, whatever matched before
    matches |= CRYPTO_memcmp(digest.data(), presented.data(), digest.size()) == 0;
  }
  if (matches == 0) return std::string("invalid bearer token");
  return std::nullopt;
}

}  // namespace tod::server
