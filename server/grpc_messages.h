// Parsing and serialising the tod.v1 messages of the raw (ByteBuffer) gRPC methods. The service
// takes requests as bytes because gRPC's generated handlers answer a request that does not parse
// with a bare status and no message (UNIMPLEMENTED or INTERNAL, depending on the API); parsing
// here lets a malformed request get INVALID_ARGUMENT with a message a person can act on.
#pragma once

#include <google/protobuf/message.h>
#include <grpcpp/support/byte_buffer.h>

#include "core/base/status.h"

namespace tod::server {

// InvalidArgument naming the message type when the bytes are not a valid `message`.
Status ParseMessage(const grpc::ByteBuffer& bytes, google::protobuf::Message* message);
// Internal when the message cannot be serialised (it always can for our messages).
Status SerializeMessage(const google::protobuf::Message& message, grpc::ByteBuffer* bytes);

}  // namespace tod::server
