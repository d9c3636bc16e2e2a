// Everything the HTTP front end reads from a client is bounded by one of these limits, so that no
// client, slow or hostile, can take more than its share of memory, sockets or time.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace tod::server::http {

struct HttpLimits {
  // Request line plus all header fields, bytes. A longer header is refused with 431.
  uint32_t max_header_bytes = 16 * 1024;
  // Decoded request body, bytes, counted while it arrives (chunked bodies too): 413.
  uint64_t max_body_bytes = 16u << 20;
  // Body bytes all connections together may hold while reading and processing requests. A request
  // declaring a length is charged that length, a chunked one max_body_bytes; 503 when exhausted.
  uint64_t max_buffered_bytes = 256u << 20;
  // From the first byte of a request to its last body byte, however the bytes trickle in: 408.
  std::chrono::milliseconds request_timeout{30'000};
  // A connection with no request in progress is closed after this long.
  std::chrono::milliseconds idle_timeout{60'000};
  // Writing one response; a client that does not read its answer loses the connection.
  std::chrono::milliseconds write_timeout{30'000};
  // Open connections, in total and per client address; further connections get 503 and close.
  int max_connections = 512;
  int max_connections_per_client = 64;
};

}  // namespace tod::server::http
