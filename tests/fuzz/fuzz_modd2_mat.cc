// Fuzzes the MODDv2 annotation path: a MAT file (the fuzzer's bytes, written to a temporary file
// because libmatio only opens paths) read by ReadModd2Annotation, then turned into masks and
// instances by SampleFromModd2Annotation for a small frame, as Modd2Dataset::Load does.
// libmatio itself is not instrumented (Debian's build): a bug inside it shows as a crash, not as
// an ASan report, and it gives the fuzzer no coverage; our code around it is instrumented.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/modd2/modd2_reader.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;

std::string& TempPath() {
  static std::string path;
  return path;
}

void RemoveTemp() { std::remove(TempPath().c_str()); }

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One file per process (libFuzzer's -jobs/-fork run several), in memory when /dev/shm exists.
  const char* dir = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
  TempPath() = std::string(dir) + "/tod_fuzz_modd2_" + std::to_string(::getpid()) + ".mat";
  std::atexit(RemoveTemp);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::FILE* file = std::fopen(TempPath().c_str(), "wb");
    Check(file != nullptr);
    Check(size == 0 || std::fwrite(data, 1, size, file) == size);
    std::fclose(file);
  }
  const tod::Result<tod::Modd2Annotation> annotation = tod::ReadModd2Annotation(TempPath());
  if (!annotation.ok()) {
    Check(!annotation.status().message().empty());
    return 0;
  }
  // A small frame keeps each run fast; the geometry scales with the annotation's coordinates,
  // which are whatever the file says.
  const cv::Mat3b image(48, 64, cv::Vec3b(120, 80, 40));
  const tod::Sample sample = tod::SampleFromModd2Annotation(*annotation, image, "fuzz");
  Check(sample.road.size() == image.size() && sample.obstacle.size() == image.size() &&
        sample.ignore.size() == image.size());
  const cv::Rect frame(0, 0, image.cols, image.rows);
  for (const tod::ObstacleInstance& instance : sample.instances) {
    Check(!instance.box.empty() && (instance.box.rect() & frame) == instance.box.rect());
    Check(instance.mask.rows == instance.box.h && instance.mask.cols == instance.box.w);
  }
  return 0;
}
