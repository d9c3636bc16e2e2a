// The one binary encoding of every model file (random forests, the pixel edge classifier, the
// occlusion classifier): integers fixed-width little-endian, floats as their IEEE-754 bit
// patterns, strings and vectors prefixed by a u64 count, and a file starting with a magic number
// and a u32 format version. The encoding is the same on every host, so a bundle moves between
// machines.
//
// BinaryWriter appends to a string (the caller writes it with WriteFileAtomically). BinaryReader
// walks a byte view and trusts nothing, since model files come from disk and fuzzers: every read
// is bounds-checked, a count is refused before anything is allocated for it when the bytes left
// cannot hold it, and the first failure sticks (later reads return zeros and leave the status
// alone), so a loader reads a group of fields and checks status() once, and the status names the
// source, the field and the offset where the bytes ran out.
//
// A model type T follows one convention: `Status T::Save(BinaryWriter&) const` and
// `static Result<T> T::Load(BinaryReader&)`; EncodeModel / DecodeModel turn it into file bytes.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/status.h"

namespace tod {

// The element types a vector may hold (each has a fixed encoded width: its sizeof).
template <typename T>
concept BinaryScalar = std::same_as<T, std::uint8_t> || std::same_as<T, std::uint32_t> ||
    std::same_as<T, std::uint64_t> || std::same_as<T, std::int32_t> || std::same_as<T, float> ||
    std::same_as<T, double>;

class BinaryWriter {
 public:
  void U8(std::uint8_t value);
  void U32(std::uint32_t value);
  void U64(std::uint64_t value);
  void I32(std::int32_t value);
  void F32(float value);
  void F64(double value);
  // Bytes as they are, no length (a magic number, a fixed-size block).
  void Raw(std::string_view bytes);
  // u64 length, then the bytes.
  void String(std::string_view text);
  // u64 count, then each value.
  template <BinaryScalar T>
  void Vector(std::span<const T> values);
  // The start of a file: the magic number, then the u32 format version.
  void Header(std::string_view magic, std::uint32_t version);

  std::size_t size() const { return bytes_.size(); }
  const std::string& bytes() const { return bytes_; }
  // What was written from `offset` on (e.g. to checksum one part of a file).
  std::string_view BytesSince(std::size_t offset) const;
  std::string Release() && { return std::move(bytes_); }

 private:
  void Unsigned(std::uint64_t value, int width);
  std::string bytes_;
};

class BinaryReader {
 public:
  static constexpr std::uint64_t kNoLimit = std::numeric_limits<std::uint64_t>::max();

  // `bytes` must outlive the reader. `source` (e.g. the file path) begins every error message.
  BinaryReader(std::string_view bytes, std::string source);

  // `field` names what is read, for the message when the bytes run out.
  std::uint8_t U8(std::string_view field);
  std::uint32_t U32(std::string_view field);
  std::uint64_t U64(std::string_view field);
  std::int32_t I32(std::string_view field);
  float F32(std::string_view field);
  double F64(std::string_view field);
  // `size` bytes as they are: a view into the input (empty after a failure).
  std::string_view Raw(std::size_t size, std::string_view field);
  // A u64 length, then the bytes; a length over max_size or over what is left fails.
  std::string String(std::string_view field, std::uint64_t max_size = kNoLimit);
  // A u64 count, then the values; a count over max_count or over what is left fails.
  template <BinaryScalar T>
  std::vector<T> Vector(std::string_view field, std::uint64_t max_count = kNoLimit);
  // Reads the magic number and the version. Another magic is InvalidArgument (not this kind of
  // file), another version FailedPrecondition (written by another build); `kind` names the file
  // type in the message ("random forest").
  Status Header(std::string_view magic, std::uint32_t version, std::string_view kind);

  // Fails unless `count` items of `item_bytes` each are left to read. A loader calls it on a
  // count read from the file before reserving memory for that many items.
  bool Expect(std::uint64_t count, std::size_t item_bytes, std::string_view field);
  // Fails when bytes are left over: a file is exactly one model.
  Status ExpectEnd();
  // Records a structural problem the loader found (DataLoss, "<source>: <problem>") and returns
  // it; the first failure stays the status.
  Status Corrupt(const std::string& problem);

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  const std::string& source() const { return source_; }
  std::size_t position() const { return position_; }
  std::size_t remaining() const { return bytes_.size() - position_; }
  // What was read from `offset` on (e.g. to verify a checksum over one part of a file).
  std::string_view BytesSince(std::size_t offset) const;

 private:
  // The next `size` bytes, or nullptr (and the status set) if fewer are left.
  const unsigned char* Take(std::size_t size, std::string_view field);
  std::uint64_t Unsigned(int width, std::string_view field);
  void Fail(Status status);
  void FailDataLoss(const std::string& problem);  // as Corrupt

  std::string_view bytes_;
  std::size_t position_ = 0;
  std::string source_;
  Status status_;
};

template <BinaryScalar T>
void BinaryWriter::Vector(std::span<const T> values) {
  U64(values.size());
  for (const T value : values) {
    if constexpr (std::same_as<T, std::uint8_t>) U8(value);
    if constexpr (std::same_as<T, std::uint32_t>) U32(value);
    if constexpr (std::same_as<T, std::uint64_t>) U64(value);
    if constexpr (std::same_as<T, std::int32_t>) I32(value);
    if constexpr (std::same_as<T, float>) F32(value);
    if constexpr (std::same_as<T, double>) F64(value);
  }
}

template <BinaryScalar T>
std::vector<T> BinaryReader::Vector(std::string_view field, std::uint64_t max_count) {
  const std::uint64_t count = U64(field);
  if (!ok()) return {};
  if (count > max_count) {
    FailDataLoss(std::string(field) + " claims " + std::to_string(count) + " values (limit " +
                 std::to_string(max_count) + ")");
    return {};
  }
  if (!Expect(count, sizeof(T), field)) return {};
  std::vector<T> values;
  values.reserve(static_cast<std::size_t>(count));
  for (std::uint64_t i = 0; i < count; ++i) {
    if constexpr (std::same_as<T, std::uint8_t>) values.push_back(U8(field));
    if constexpr (std::same_as<T, std::uint32_t>) values.push_back(U32(field));
    if constexpr (std::same_as<T, std::uint64_t>) values.push_back(U64(field));
    if constexpr (std::same_as<T, std::int32_t>) values.push_back(I32(field));
    if constexpr (std::same_as<T, float>) values.push_back(F32(field));
    if constexpr (std::same_as<T, double>) values.push_back(F64(field));
  }
  return values;
}

// The file bytes of `model`.
template <typename Model>
Result<std::string> EncodeModel(const Model& model) {
  BinaryWriter out;
  if (Status status = model.Save(out); !status.ok()) return status;
  return std::move(out).Release();
}

// `Model` from all of `bytes` (left-over bytes are an error too); `source` names them in errors.
template <typename Model>
Result<Model> DecodeModel(std::string_view bytes, std::string source) {
  BinaryReader in(bytes, std::move(source));
  Result<Model> model = Model::Load(in);
  if (!model.ok()) return model;
  if (Status status = in.ExpectEnd(); !status.ok()) return status;
  return model;
}

}  // namespace tod
