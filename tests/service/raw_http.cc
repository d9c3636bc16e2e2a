#include "tests/service/raw_http.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <fstream>
#include <sstream>

namespace tod::server::testing {
namespace {

using Clock = std::chrono::steady_clock;

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return static_cast<int>(std::max<long long>(0, left.count()));
}

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// Parses the header block (without the final blank line).
std::optional<RawResponse> ParseHead(const std::string& head) {
  std::istringstream lines(head);
  std::string line;
  if (!std::getline(lines, line)) return std::nullopt;
  RawResponse response;
  // "HTTP/1.1 413 Payload Too Large"
  const size_t space = line.find(' ');
  if (line.rfind("HTTP/1.", 0) != 0 || space == std::string::npos) return std::nullopt;
  response.status = std::atoi(line.c_str() + space + 1);
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    response.headers[Lower(line.substr(0, colon))] = value;
  }
  return response;
}

}  // namespace

RawConnection::RawConnection(int port) { Connect(port, 0); }

RawConnection::RawConnection(int port, int receive_buffer_bytes) {
  Connect(port, receive_buffer_bytes);
}

void RawConnection::Connect(int port, int receive_buffer_bytes) {
  fd_ = socket(AF_INET, SOCK_STREAM, 0);
  if (fd_ < 0) return;
  if (receive_buffer_bytes > 0) {
    setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof(receive_buffer_bytes));
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<uint16_t>(port));
  if (connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd_);
    fd_ = -1;
  }
}

RawConnection::~RawConnection() {
  if (fd_ >= 0) close(fd_);
}

bool RawConnection::Send(std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<size_t>(n));
  }
  return true;
}

bool RawConnection::Readable(std::chrono::milliseconds wait) const {
  pollfd fd{fd_, POLLIN, 0};
  return poll(&fd, 1, static_cast<int>(wait.count())) > 0;
}

std::optional<RawResponse> RawConnection::ReadResponse(std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  std::optional<RawResponse> response;
  size_t body_start = 0;
  bool eof = false;
  for (;;) {
    if (!response) {
      if (const size_t end = received_.find("\r\n\r\n"); end != std::string::npos) {
        response = ParseHead(received_.substr(0, end));
        if (!response) return std::nullopt;
        body_start = end + 4;
      }
    }
    if (response) {
      const auto length = response->headers.find("content-length");
      if (length != response->headers.end()) {
        const size_t want = std::stoul(length->second);
        if (received_.size() - body_start >= want) {
          response->body = received_.substr(body_start, want);
          received_.erase(0, body_start + want);
          return response;
        }
      }
      if (eof) {
        response->body = received_.substr(body_start);
        received_.clear();
        return response;
      }
    }
    if (eof) return std::nullopt;
    pollfd fd{fd_, POLLIN, 0};
    if (poll(&fd, 1, RemainingMs(deadline)) <= 0) return std::nullopt;  // timed out
    char buffer[65536];
    const ssize_t n = recv(fd_, buffer, sizeof(buffer), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      eof = true;  // closed or reset: whatever arrived is all there is
    } else {
      received_.append(buffer, static_cast<size_t>(n));
    }
  }
}

RawConnection::Streamed RawConnection::StreamUntilAnswered(std::string_view head,
                                                           std::string_view piece, uint64_t limit,
                                                           std::chrono::milliseconds timeout) {
  Streamed result;
  const Clock::time_point deadline = Clock::now() + timeout;
  std::string_view pending = head;
  const int flags = fcntl(fd_, F_GETFL);
  fcntl(fd_, F_SETFL, flags | O_NONBLOCK);
  while (result.sent < limit && Clock::now() < deadline) {
    pollfd fd{fd_, POLLIN | POLLOUT, 0};
    if (poll(&fd, 1, RemainingMs(deadline)) <= 0) break;
    if (fd.revents & (POLLIN | POLLHUP | POLLERR)) break;  // the server answered (or hung up)
    if (pending.empty()) pending = piece;
    const ssize_t n = send(fd_, pending.data(), pending.size(), MSG_NOSIGNAL);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0) break;  // reset or broken pipe
    pending.remove_prefix(static_cast<size_t>(n));
    result.sent += static_cast<uint64_t>(n);
  }
  fcntl(fd_, F_SETFL, flags);
  result.response = ReadResponse(std::chrono::milliseconds(std::max(1000, RemainingMs(deadline))));
  return result;
}

std::optional<uint64_t> RawConnection::SendRepeatedWhileRoom(std::string_view piece,
                                                             uint64_t limit) {
  uint64_t sent = 0;
  while (sent < limit) {
    const std::string_view rest = piece.substr(piece_sent_);
    const size_t want = static_cast<size_t>(std::min<uint64_t>(rest.size(), limit - sent));
    const ssize_t n = send(fd_, rest.data(), want, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;  // full: nobody reads it
    if (n <= 0) return std::nullopt;
    sent += static_cast<uint64_t>(n);
    piece_sent_ = (piece_sent_ + static_cast<size_t>(n)) % piece.size();
  }
  return sent;
}

std::optional<char> RawConnection::ReadByte(std::chrono::milliseconds wait, bool* closed) {
  *closed = false;
  if (!Readable(wait)) return std::nullopt;
  char byte = 0;
  const ssize_t n = recv(fd_, &byte, 1, 0);
  if (n == 1) return byte;
  *closed = !(n < 0 && (errno == EINTR || errno == EAGAIN));
  return std::nullopt;
}

bool RawConnection::WaitClosed(std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  char buffer[65536];
  for (;;) {
    pollfd fd{fd_, POLLIN, 0};
    if (poll(&fd, 1, RemainingMs(deadline)) <= 0) return false;  // timed out, still open
    const ssize_t n = recv(fd_, buffer, sizeof(buffer), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;  // EOF or reset
  }
}

MemoryKb ProcessMemory(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  MemoryKb memory;
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) memory.rss = std::atoll(line.c_str() + 6);
    if (line.rfind("VmHWM:", 0) == 0) memory.peak = std::atoll(line.c_str() + 6);
  }
  return memory;
}

std::string HttpChunk(const std::string& data) {
  std::ostringstream chunk;
  chunk << std::hex << data.size() << "\r\n" << data << "\r\n";
  return chunk.str();
}

}  // namespace tod::server::testing
