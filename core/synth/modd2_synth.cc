// WriteModd2SynthDataset: synthetic frames written in the exact MODDv2 layout (modd2_synth.h).
#include "core/synth/modd2_synth.h"

#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/imgcodecs.hpp>

namespace tod {
namespace {

namespace fs = std::filesystem;

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};

// A column-major double matrix variable (a struct field, so no name).
std::unique_ptr<matvar_t, MatVarFreer> DoubleMatrix(std::size_t rows, std::size_t cols,
                                                    std::vector<double> column_major) {
  std::size_t dims[2] = {rows, cols};
  return std::unique_ptr<matvar_t, MatVarFreer>(
      Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                    column_major.empty() ? nullptr : column_major.data(), 0));
}

Status WriteAnnotationMat(const std::string& path, const Modd2Annotation& annotation) {
  const std::size_t n = annotation.sea_edge.size();
  std::vector<double> sea_edge(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    sea_edge[i] = annotation.sea_edge[i].x;
    sea_edge[n + i] = annotation.sea_edge[i].y;
  }
  const std::size_t m = annotation.obstacles.size();
  std::vector<double> obstacles(4 * m);
  for (std::size_t i = 0; i < m; ++i) {
    const cv::Rect2d& b = annotation.obstacles[i];
    obstacles[i] = b.x;
    obstacles[m + i] = b.y;
    obstacles[2 * m + i] = b.width;
    obstacles[3 * m + i] = b.height;
  }
  std::unique_ptr<mat_t, MatFileCloser> mat(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5));
  if (!mat) return Status::Unavailable(path + ": cannot create the MAT file");
  const char* fields[] = {"sea_edge", "obstacles"};
  std::size_t struct_dims[2] = {1, 1};
  std::unique_ptr<matvar_t, MatVarFreer> annotations(
      Mat_VarCreateStruct("annotations", 2, struct_dims, fields, 2));
  auto sea_edge_var = DoubleMatrix(n, 2, std::move(sea_edge));
  auto obstacles_var = DoubleMatrix(m, 4, std::move(obstacles));
  if (!annotations || !sea_edge_var || !obstacles_var) {
    return Status::Internal(path + ": cannot build the MAT variables");
  }
  // The struct takes ownership of its fields.
  Mat_VarSetStructFieldByName(annotations.get(), "sea_edge", 0, sea_edge_var.release());
  Mat_VarSetStructFieldByName(annotations.get(), "obstacles", 0, obstacles_var.release());
  if (Mat_VarWrite(mat.get(), annotations.get(), MAT_COMPRESSION_ZLIB) != 0) {
    return Status::Unavailable(path + ": cannot write variable 'annotations'");
  }
  return Status::Ok();
}

std::string FrameStem(long long frame) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%08lldL", frame);
  return buffer;
}

long long SequenceStart(const std::string& name, long long* end) {
  // kopeNN-CC-SSSSSSSS-EEEEEEEE
  const std::size_t last = name.rfind('-');
  const std::size_t prev = name.rfind('-', last - 1);
  *end = std::stoll(name.substr(last + 1));
  return std::stoll(name.substr(prev + 1, last - prev - 1));
}

Status MakeDirectories(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status::Unavailable(dir.string() + ": cannot create directory: " + ec.message());
  return Status::Ok();
}

}  // namespace

Modd2Split Modd2SynthSplit(int sequences) {
  const Modd2Split& defaults = DefaultModd2Split();
  std::vector<std::string> test_pool = defaults.test;
  test_pool.insert(test_pool.end(), defaults.excluded.begin(), defaults.excluded.end());
  const int n = std::clamp(sequences, 1, static_cast<int>(Modd2SequenceNames().size()));
  int train_count = 1;
  if (n >= 2)
    train_count = std::clamp(static_cast<int>(std::lround(kModd2TrainFraction * n)), 1, n - 1);
  train_count = std::min<int>(train_count, static_cast<int>(defaults.train.size()));
  const int test_count = std::min<int>(n - train_count, static_cast<int>(test_pool.size()));
  Modd2Split split;
  split.source = "synthetic MODDv2 dataset, " + std::to_string(n) + " sequences";
  split.train.assign(defaults.train.begin(), defaults.train.begin() + train_count);
  split.test.assign(test_pool.begin(), test_pool.begin() + test_count);
  return split;
}

Status WriteModd2SynthDataset(const std::string& root, int sequences, int frames_per_sequence,
                              int width, int height, std::uint64_t seed) {
  const int known = static_cast<int>(Modd2SequenceNames().size());
  if (sequences < 1 || sequences > known) {
    return Status::InvalidArgument("synthetic MODDv2: sequences must be in 1.." +
                                   std::to_string(known) + ", got " + std::to_string(sequences));
  }
  if (width < kModd2SynthMinWidth || height < kModd2SynthMinHeight) {
    return Status::InvalidArgument("synthetic MODDv2: image size must be at least " +
                                   std::to_string(kModd2SynthMinWidth) + "x" +
                                   std::to_string(kModd2SynthMinHeight) + ", got " +
                                   std::to_string(width) + "x" + std::to_string(height));
  }
  const Modd2Split split = Modd2SynthSplit(sequences);
  std::vector<std::string> names = split.train;
  names.insert(names.end(), split.test.begin(), split.test.end());
  for (const std::string& name : names) {
    long long end = 0;
    const long long start = SequenceStart(name, &end);
    if (frames_per_sequence < 1 || frames_per_sequence > end - start) {
      return Status::InvalidArgument("synthetic MODDv2: frames_per_sequence must be in 1.." +
                                     std::to_string(end - start) + " for sequence " + name +
                                     ", got " + std::to_string(frames_per_sequence));
    }
  }

  const fs::path root_path(root);
  for (std::size_t s = 0; s < names.size(); ++s) {
    const std::string& name = names[s];
    long long end = 0;
    const long long start = SequenceStart(name, &end);
    const fs::path frames_dir = root_path / "video_data" / name / "frames";
    const fs::path annotation_dir = root_path / "annotationsV2" / name / "ground_truth";
    if (Status st = MakeDirectories(frames_dir); !st.ok()) return st;
    if (Status st = MakeDirectories(annotation_dir); !st.ok()) return st;
    // Frame S has an annotation but no image in the real data; reproduce that.
    for (int f = 0; f <= frames_per_sequence; ++f) {
      const long long frame_number = start + f;
      const Modd2SynthFrame frame =
          GenerateModd2SynthFrame(width, height, Modd2SynthFrameSeed(seed, static_cast<int>(s), f));
      const std::string stem = FrameStem(frame_number);
      const std::string mat_path = (annotation_dir / (stem + ".mat")).string();
      if (Status st = WriteAnnotationMat(mat_path, frame.annotation); !st.ok()) return st;
      if (f == 0) continue;
      const std::string image_path = (frames_dir / (stem + ".jpg")).string();
      if (!cv::imwrite(image_path, frame.image, {cv::IMWRITE_JPEG_QUALITY, 95})) {
        return Status::Unavailable(image_path + ": cannot write the image");
      }
    }
  }
  const fs::path split_path = root_path / kModd2SplitFileName;
  std::ofstream split_file(split_path);
  split_file << FormatModd2SplitFile(split);
  if (!split_file) return Status::Unavailable(split_path.string() + ": cannot write the split");
  return Status::Ok();
}

}  // namespace tod
