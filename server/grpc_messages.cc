#include "server/grpc_messages.h"

#include <grpcpp/impl/codegen/proto_utils.h>
#include <grpcpp/support/proto_buffer_reader.h>

#include <string>

namespace tod::server {

Status ParseMessage(const grpc::ByteBuffer& bytes, google::protobuf::Message* message) {
  // The reader consumes its buffer; a copy shares the slices, so this copies no payload.
  grpc::ByteBuffer copy(bytes);
  const std::string type = message->GetDescriptor()->full_name();
  grpc::ProtoBufferReader reader(&copy);
  if (!reader.status().ok() || !message->ParseFromZeroCopyStream(&reader) ||
      !reader.status().ok()) {
    return Status::InvalidArgument("malformed request: " + std::to_string(bytes.Length()) +
                                   " bytes are not a valid " + type + " protobuf message");
  }
  return Status::Ok();
}

Status SerializeMessage(const google::protobuf::Message& message, grpc::ByteBuffer* bytes) {
  bool own_buffer = false;
  const grpc::Status status =
      grpc::SerializationTraits<google::protobuf::Message>::Serialize(message, bytes, &own_buffer);
  if (!status.ok())
    return Status::Internal("cannot serialise the response: " + status.error_message());
  return Status::Ok();
}

}  // namespace tod::server
