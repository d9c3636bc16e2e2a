#include "core/base/binary_io.h"

#include <algorithm>
#include <bit>

namespace tod {

void BinaryWriter::Unsigned(std::uint64_t value, int width) {
  for (int i = 0; i < width; ++i) bytes_.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

void BinaryWriter::U8(std::uint8_t value) { Unsigned(value, 1); }
void BinaryWriter::U32(std::uint32_t value) { Unsigned(value, 4); }
void BinaryWriter::U64(std::uint64_t value) { Unsigned(value, 8); }
void BinaryWriter::I32(std::int32_t value) { U32(static_cast<std::uint32_t>(value)); }
void BinaryWriter::F32(float value) { U32(std::bit_cast<std::uint32_t>(value)); }
void BinaryWriter::F64(double value) { U64(std::bit_cast<std::uint64_t>(value)); }
void BinaryWriter::Raw(std::string_view bytes) { bytes_.append(bytes); }

void BinaryWriter::String(std::string_view text) {
  U64(text.size());
  Raw(text);
}

void BinaryWriter::Header(std::string_view magic, std::uint32_t version) {
  Raw(magic);
  U32(version);
}

std::string_view BinaryWriter::BytesSince(std::size_t offset) const {
  return std::string_view(bytes_).substr(std::min(offset, bytes_.size()));
}

BinaryReader::BinaryReader(std::string_view bytes, std::string source)
    : bytes_(bytes), source_(std::move(source)) {}

void BinaryReader::Fail(Status status) {
  if (status_.ok()) status_ = std::move(status);
}

void BinaryReader::FailDataLoss(const std::string& problem) {
  Fail(Status::DataLoss(source_ + ": " + problem));
}

Status BinaryReader::Corrupt(const std::string& problem) {
  FailDataLoss(problem);
  return status_;
}

bool BinaryReader::Expect(std::uint64_t count, std::size_t item_bytes, std::string_view field) {
  if (!ok()) return false;
  // Divided rather than multiplied: a hostile count times the item size may overflow.
  if (item_bytes == 0 || count <= remaining() / item_bytes) return true;
  Fail(Status::DataLoss(source_ + ": truncated: " + std::string(field) + " claims " +
                        std::to_string(count) + " x " + std::to_string(item_bytes) +
                        " bytes at offset " + std::to_string(position_) + ", only " +
                        std::to_string(remaining()) + " left"));
  return false;
}

const unsigned char* BinaryReader::Take(std::size_t size, std::string_view field) {
  if (!ok()) return nullptr;
  if (size > remaining()) {
    Fail(Status::DataLoss(source_ + ": truncated at offset " + std::to_string(position_) +
                          " while reading " + std::string(field) + " (" + std::to_string(size) +
                          " bytes, " + std::to_string(remaining()) + " left)"));
    return nullptr;
  }
  const auto* data = reinterpret_cast<const unsigned char*>(bytes_.data() + position_);
  position_ += size;
  return data;
}

std::uint64_t BinaryReader::Unsigned(int width, std::string_view field) {
  const unsigned char* data = Take(static_cast<std::size_t>(width), field);
  if (data == nullptr) return 0;
  std::uint64_t value = 0;
  for (int i = width - 1; i >= 0; --i) value = (value << 8) | data[i];
  return value;
}

std::uint8_t BinaryReader::U8(std::string_view field) {
  return static_cast<std::uint8_t>(Unsigned(1, field));
}
std::uint32_t BinaryReader::U32(std::string_view field) {
  return static_cast<std::uint32_t>(Unsigned(4, field));
}
std::uint64_t BinaryReader::U64(std::string_view field) { return Unsigned(8, field); }
std::int32_t BinaryReader::I32(std::string_view field) {
  return static_cast<std::int32_t>(U32(field));
}
float BinaryReader::F32(std::string_view field) { return std::bit_cast<float>(U32(field)); }
double BinaryReader::F64(std::string_view field) { return std::bit_cast<double>(U64(field)); }

std::string_view BinaryReader::Raw(std::size_t size, std::string_view field) {
  const unsigned char* data = Take(size, field);
  if (data == nullptr) return {};
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

std::string BinaryReader::String(std::string_view field, std::uint64_t max_size) {
  const std::uint64_t size = U64(field);
  if (!ok()) return {};
  if (size > max_size) {
    FailDataLoss(std::string(field) + " claims " + std::to_string(size) + " bytes (limit " +
                 std::to_string(max_size) + ")");
    return {};
  }
  if (!Expect(size, 1, field)) return {};
  return std::string(Raw(static_cast<std::size_t>(size), field));
}

Status BinaryReader::Header(std::string_view magic, std::uint32_t version, std::string_view kind) {
  const std::string_view found = Raw(magic.size(), "the magic number");
  if (!ok()) return status_;
  if (found != magic) {
    Fail(Status::InvalidArgument(source_ + ": not a " + std::string(kind) + " (bad magic number)"));
    return status_;
  }
  const std::uint32_t found_version = U32("the format version");
  if (!ok()) return status_;
  if (found_version != version) {
    Fail(Status::FailedPrecondition(source_ + ": " + std::string(kind) + " format version " +
                                    std::to_string(found_version) + ", this build reads version " +
                                    std::to_string(version)));
  }
  return status_;
}

Status BinaryReader::ExpectEnd() {
  if (ok() && remaining() > 0) {
    FailDataLoss(std::to_string(remaining()) +
                 " unexpected bytes after the end of the model (offset " +
                 std::to_string(position_) + ")");
  }
  return status_;
}

std::string_view BinaryReader::BytesSince(std::size_t offset) const {
  return bytes_.substr(std::min(offset, position_), position_ - std::min(offset, position_));
}

}  // namespace tod
