// A plain TCP client on 127.0.0.1 for the HTTP hardening tests: it sends exactly the bytes a
// test gives (malformed, endless, trickling), reads back one HTTP/1.1 response, or reads nothing
// (or one byte at a time) to play a client that does not take its answers.
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
  // Also caps the socket's receive buffer (before connecting, so that the window the server sees
  // stays that small): answers the test does not read then back up into the server quickly.
  RawConnection(int port, int receive_buffer_bytes);
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

  // Without blocking: sends `piece` again and again (pipelined requests) for as long as the socket
  // takes bytes, at most `limit` bytes this call; a piece cut short is finished first next call.
  // The bytes sent (0: the socket is full, the server is not reading), or nullopt when the
  // connection broke.
  std::optional<uint64_t> SendRepeatedWhileRoom(std::string_view piece, uint64_t limit);
  // One byte if one arrives within `wait`; nullopt on timeout; EOF or an error: `closed` is set.
  std::optional<char> ReadByte(std::chrono::milliseconds wait, bool* closed);
  // Reads and discards until the server ends the connection (EOF or reset); false if it is still
  // open after `timeout`.
  bool WaitClosed(std::chrono::milliseconds timeout);

 private:
  void Connect(int port, int receive_buffer_bytes);

  int fd_ = -1;
  std::string received_;
  size_t piece_sent_ = 0;  // SendRepeatedWhileRoom: bytes of the current piece already sent
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
