#include "core/modd2/mat5_bounds.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace tod {
namespace {

// MAT-File Level 5 data types and array classes used here (MathWorks' MAT-file format document).
constexpr uint32_t kMiInt32 = 5;
constexpr uint32_t kMiUint32 = 6;
constexpr uint32_t kMiMatrix = 14;
constexpr uint32_t kMiCompressed = 15;
constexpr uint32_t kClassCell = 1;
constexpr uint32_t kClassStruct = 2;
constexpr uint32_t kClassObject = 3;
constexpr uint32_t kClassSparse = 5;
constexpr uint32_t kClassFunction = 16;
constexpr uint32_t kClassOpaque = 17;
constexpr int kMaxDepth = 32;
constexpr unsigned kVersion5 = 0x0100;
constexpr unsigned kVersion73 = 0x0200;

Status NotValidMat(const std::string& what, const std::string& problem) {
  return Status::DataLoss(what + ": not a valid MAT file (" + problem + ")");
}

class Walker {
 public:
  Walker(bool swap, std::string what) : swap_(swap), what_(std::move(what)) {}

  // A sequence of data elements (the file after its header, or an inflated variable).
  Status Elements(std::string_view data, bool top_level) {
    while (data.size() >= 8) {
      uint32_t type = 0;
      uint32_t size = 0;
      std::string_view payload;
      if (Status s = Tag(&data, &type, &size, &payload); !s.ok()) return s;
      if (type == kMiCompressed && top_level) {
        std::string inflated;
        if (Status s = Inflate(payload, &inflated); !s.ok()) return s;
        if (Status s = Elements(inflated, false); !s.ok()) return s;
      } else if (type == kMiMatrix) {
        // A variable whose tag claims no bytes: libmatio reads its header from the bytes that
        // follow all the same (a fuzzed file made it allocate a 1 x 687 M struct this way), while
        // the walk would take those bytes for further elements. An empty matrix is a value inside
        // a cell or struct, never a variable of its own.
        if (payload.empty()) return Corrupt("a variable of 0 bytes");
        if (Status s = Matrix(payload, 0); !s.ok()) return s;
      }
    }
    return Status::Ok();
  }

 private:
  uint32_t U32(const char* p) const {
    const auto* b = reinterpret_cast<const unsigned char*>(p);
    return swap_ ? (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | b[3]
                 : (uint32_t{b[3]} << 24) | (uint32_t{b[2]} << 16) | (uint32_t{b[1]} << 8) | b[0];
  }

  Status Corrupt(const std::string& problem) const { return NotValidMat(what_, problem); }

  // One data element from the front of `data`: its type, byte count and payload (the small
  // format packs up to 4 bytes into the tag). Advances past the 8-byte padding.
  Status Tag(std::string_view* data, uint32_t* type, uint32_t* size,
             std::string_view* payload) const {
    if (data->size() < 8) return Corrupt("truncated element tag");
    const uint32_t first = U32(data->data());
    if ((first >> 16) != 0) {  // small data element
      *type = first & 0xFFFF;
      *size = first >> 16;
      if (*size > 4) return Corrupt("small element of more than 4 bytes");
      *payload = data->substr(4, *size);
      data->remove_prefix(8);
      return Status::Ok();
    }
    *type = first;
    *size = U32(data->data() + 4);
    if (*size > data->size() - 8) return Corrupt("element larger than its container");
    *payload = data->substr(8, *size);
    // Compressed elements are not padded; the others are padded to 8 bytes (if room is left).
    const size_t padded = *type == kMiCompressed ? *size : (size_t{*size} + 7) / 8 * 8;
    data->remove_prefix(std::min(data->size(), 8 + padded));
    return Status::Ok();
  }

  Status Inflate(std::string_view in, std::string* out) const {
    z_stream z{};
    if (inflateInit(&z) != Z_OK) return Status::Internal("zlib inflateInit failed");
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
    z.avail_in = static_cast<uInt>(in.size());
    std::vector<char> chunk(1 << 16);
    int result = Z_OK;
    while (result == Z_OK) {
      z.next_out = reinterpret_cast<Bytef*>(chunk.data());
      z.avail_out = static_cast<uInt>(chunk.size());
      result = inflate(&z, Z_NO_FLUSH);
      out->append(chunk.data(), chunk.size() - z.avail_out);
      if (out->size() > kMaxMatFileBytes) {
        inflateEnd(&z);
        return Corrupt("a compressed variable inflates to more than " +
                       std::to_string(kMaxMatFileBytes) + " bytes");
      }
      if (result == Z_BUF_ERROR && z.avail_in == 0) break;  // truncated: matio reports it
    }
    inflateEnd(&z);
    return Status::Ok();
  }

  // A miMATRIX payload: array flags, dimensions, name, then the class's own subelements.
  Status Matrix(std::string_view data, int depth) {
    if (depth > kMaxDepth) return Corrupt("arrays nested more than 32 deep");
    if (data.empty()) return Status::Ok();  // an empty matrix element (allowed in cells)
    const size_t own_bytes = data.size();
    uint32_t type = 0, size = 0;
    std::string_view flags, dims, name;
    if (Status s = Tag(&data, &type, &size, &flags); !s.ok()) return s;
    // libmatio reads the flags as one 8-byte uint32 element whatever their tag claims, and the
    // dimensions right after those 8 bytes: a fuzzed file whose flags tag claimed 110 bytes hid
    // dimensions of 3 x -268 M from this walk, and libmatio allocated 48 GB for them.
    if (type != kMiUint32 || size != 8) return Corrupt("array flags are not 8 bytes of uint32");
    const uint32_t array_class = U32(flags.data()) & 0xFF;
    if (array_class < kClassCell || array_class > kClassOpaque) {
      return Corrupt("unknown array class " + std::to_string(array_class));
    }
    // libmatio reads the second subelement as the dimensions whatever the class and, when it is
    // tagged int32, allocates 8 bytes per value its tag claims (a 424-byte file claiming a billion
    // dimensions made it allocate 8 GB). Tag checks that size against the container for every
    // class. An opaque object lays out the rest differently; libmatio 1.5.23 allocates nothing by
    // its dimensions (tried with a claim of 1.9e9 elements), but it does allocate what the next
    // tag claims (a fuzzed 392-byte file made it allocate 2 GB for a name): the walk checks every
    // remaining tag of an opaque object against its container, without interpreting them.
    if (Status s = Tag(&data, &type, &size, &dims); !s.ok()) return s;
    if (array_class == kClassOpaque) return TagsFit(data);
    uint64_t elements = 0;
    if (Status s = ElementCount(type, dims, &elements); !s.ok()) return s;
    if (Status s = Tag(&data, &type, &size, &name); !s.ok()) return s;
    switch (array_class) {
      case kClassSparse:  // stored by its non-zeros, not by its dimensions
        return TagsFit(data);
      case kClassCell:
      case kClassFunction:  // libmatio reads a function handle array as a cell array
        return Values(data, elements, 1, own_bytes, depth);
      case kClassStruct:
      case kClassObject:
        return StructValues(data, array_class, elements, own_bytes, depth);
      default:  // numeric or char: every element takes at least one stored byte
        if (elements > own_bytes) {
          return Corrupt("an array claims " + std::to_string(elements) + " elements in " +
                         std::to_string(own_bytes) + " bytes");
        }
        // Its real (and imaginary) part: libmatio allocates from what the part's tag claims, not
        // from the dimensions (a fuzzed 425-byte file whose 4 x 2 single array's data tag claimed
        // 2 GB made it ask calloc for 2^64 - 16 M bytes).
        return TagsFit(data);
    }
  }

  // Every data element of `data`, each checked against what is left of its container.
  Status TagsFit(std::string_view data) const {
    while (data.size() >= 8) {
      uint32_t type = 0, size = 0;
      std::string_view payload;
      if (Status s = Tag(&data, &type, &size, &payload); !s.ok()) return s;
    }
    return Status::Ok();
  }

  // The product of int32 dimensions (two or more), saturated at 2^40: far more than any array
  // that fits in kMaxMatFileBytes, so a saturated count is refused all the same.
  Status ElementCount(uint32_t type, std::string_view dims, uint64_t* elements) const {
    if (type != kMiInt32 || dims.size() < 8 || dims.size() % 4 != 0) {
      return Corrupt("array dimensions are not two or more int32 values");
    }
    constexpr uint64_t kSaturated = uint64_t{1} << 40;
    *elements = 1;
    for (size_t at = 0; at < dims.size(); at += 4) {
      const int32_t d = static_cast<int32_t>(U32(dims.data() + at));
      if (d < 0) return Corrupt("negative array dimension");
      *elements = d == 0 ? 0 : (*elements > kSaturated / d ? kSaturated : *elements * d);
    }
    return Status::Ok();
  }

  // A struct's (or object's) field names, then its values.
  Status StructValues(std::string_view data, uint32_t array_class, uint64_t elements,
                      size_t own_bytes, int depth) {
    uint32_t type = 0, size = 0;
    std::string_view class_name, names;
    if (array_class == kClassObject) {
      if (Status s = Tag(&data, &type, &size, &class_name); !s.ok()) return s;
    }
    // libmatio reads the field name length as 8 bytes whatever their tag says (as it should be,
    // a small int32 element), takes the length from bytes 4-7 and reads the names' tag right
    // after: a fuzzed 424-byte file whose length element was a regular 8-byte one made it read
    // the length's own value as the names' tag, claiming 4 GB, and allocate a pointer for each
    // of 516 M field names. The walk reads the two as libmatio does, so Tag checks that claim.
    if (data.size() < 8) return Corrupt("struct field name length missing");
    if ((U32(data.data()) & 0xFFFF) != kMiInt32)
      return Corrupt("struct field name length is not int32");
    const uint32_t length = U32(data.data() + 4);
    data.remove_prefix(8);
    if (Status s = Tag(&data, &type, &size, &names); !s.ok()) return s;
    const uint64_t fields = length == 0 ? 0 : names.size() / length;
    return Values(data, elements, fields, own_bytes, depth);
  }

  // `elements` x `fields` values, each a miMATRIX element of at least its 8-byte tag (libmatio
  // allocates one matvar_t per value before reading them). Divided, not multiplied: a saturated
  // element count times millions of field names would wrap around.
  Status Values(std::string_view data, uint64_t elements, uint64_t fields, size_t own_bytes,
                int depth) {
    if (fields != 0 && elements > own_bytes / 8 / fields) {
      return Corrupt("a struct or cell array claims " + std::to_string(elements) + " x " +
                     std::to_string(fields) + " values in " + std::to_string(own_bytes) + " bytes");
    }
    for (uint64_t i = 0; i < elements * fields && !data.empty(); ++i) {
      uint32_t type = 0, size = 0;
      std::string_view child;
      if (Status s = Tag(&data, &type, &size, &child); !s.ok()) return s;
      if (type != kMiMatrix) return Corrupt("a struct or cell value is not an array");
      if (Status s = Matrix(child, depth + 1); !s.ok()) return s;
    }
    return Status::Ok();
  }

  bool swap_;
  std::string what_;
};

}  // namespace

Status CheckMat5Bounds(std::string_view bytes, const std::string& what) {
  if (bytes.size() > kMaxMatFileBytes) {
    return Status::DataLoss(what + ": " + std::to_string(bytes.size()) +
                            " bytes is too large for an annotation file");
  }
  // Header: 116 bytes of text, 8 of subsystem offset, version (2 bytes), endian indicator "IM"
  // (little-endian file) or "MI". Version 0x0100 is Level 5 (MATLAB's -v6 and -v7); 0x0200 is a
  // -v7.3 file, HDF5 behind the same header, which libmatio hands to libhdf5 and is left to it.
  // Anything else is refused rather than passed on: libmatio would read it as MAT v4 (see
  // mat5_bounds.h), and a v4 file cannot hold the annotations struct anyway.
  if (bytes.size() < 128) return NotValidMat(what, "shorter than the 128-byte Level-5 header");
  const std::string_view endian = bytes.substr(126, 2);
  if (endian != "IM" && endian != "MI") return NotValidMat(what, "no Level-5 header");
  const bool swap = endian == "MI";
  const auto* v = reinterpret_cast<const unsigned char*>(bytes.data() + 124);
  const unsigned version = swap ? (v[0] << 8) | v[1] : (v[1] << 8) | v[0];
  if (version == kVersion73) return Status::Ok();
  if (version != kVersion5) return NotValidMat(what, "unknown version " + std::to_string(version));
  return Walker(swap, what).Elements(bytes.substr(128), true);
}

}  // namespace tod
