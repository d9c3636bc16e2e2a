// A split of an annotated dataset, read frame by frame so a whole split never has to sit in
// memory. Implemented by the Lost and Found reader (core/data) and the MODDv2 reader (core/modd2).
#pragma once

#include <cstddef>
#include <string>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

// Ok when i indexes a dataset of `size` frames; else the error every reader returns.
inline Status CheckFrameIndex(std::size_t i, std::size_t size) {
  if (i < size) return Status::Ok();
  return Status::InvalidArgument("frame index " + std::to_string(i) + " out of range (" +
                                 std::to_string(size) + " frames)");
}

class Dataset {
 public:
  virtual ~Dataset() = default;
  virtual std::size_t size() const = 0;
  // Stem of frame i, without reading it (for progress output and output file names).
  virtual std::string name(std::size_t i) const = 0;
  // Reads frame i fully; errors name the file and the problem.
  virtual Result<Sample> Load(std::size_t i) const = 0;
};

}  // namespace tod
