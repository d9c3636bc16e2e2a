// A plain TCP client on 127.0.0.1 for the HTTP hardening tests: it sends exactly the bytes a
// test gives (malformed, endless, trickling) and reads back one HTTP/1.1 response.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace tod::server::testing {

struct RawResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;
};

class RawConnection {
 public:
  explicit RawConnection(int port);  // connects to 127.0.0.1:port (see connected())
  ~RawConnection();
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const { return fd_ >= 0; }
  // Sends everything (blocking); false when the connection broke.
  bool Send(std::string_view bytes);
  // True when a byte (or EOF) can be read within `wait`.
  bool Readable(std::chrono::milliseconds wait) const;
  // One response: status line, headers, then a Content-Length body or everything up to EOF.
  // nullopt when no complete header arrived within `timeout` or the connection closed first.
  std::optional<RawResponse> ReadResponse(std::chrono::milliseconds timeout);

  // Sends `head`, then `piece` again and again up to `limit` bytes in all, stopping as soon as
  // the server answers or the connection breaks; then reads the answer.
  struct Streamed {
    uint64_t sent = 0;
    std::optional<RawResponse> response;
  };
  Streamed StreamUntilAnswered(std::string_view head, std::string_view piece, uint64_t limit,
                               std::chrono::milliseconds timeout);

 private:
  int fd_ = -1;
  std::string received_;
};

// Resident and peak resident memory of a process, kB (/proc/<pid>/status VmRSS, VmHWM).
struct MemoryKb {
  long long rss = 0;
  long long peak = 0;
};
MemoryKb ProcessMemory(int pid);

// One chunk of a chunked body: "<hex size>\r\n<data>\r\n".
std::string HttpChunk(const std::string& data);

}  // namespace tod::server::testing
