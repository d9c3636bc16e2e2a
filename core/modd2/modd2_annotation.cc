// ReadModd2Annotation: one per-frame MAT file (MODD2-FORMAT.md "Annotation .mat") read with
// libmatio. Level-5 files, compressed or not, any real numeric class; fields are looked up by name
// and unknown ones ignored. Every error names the file and the field.
#include <matio.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "core/modd2/mat5_bounds.h"
#include "core/modd2/modd2_reader.h"

namespace tod {
namespace {

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatFile = std::unique_ptr<mat_t, MatFileCloser>;
using MatVar = std::unique_ptr<matvar_t, MatVarFreer>;

// A dense real matrix of any numeric class, converted to double, column-major as MATLAB stores it.
struct NumericMatrix {
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<double> values;  // values[r + c * rows]
  double at(std::size_t r, std::size_t c) const { return values[r + c * rows]; }
};

template <typename T>
void AppendAs(const void* data, std::size_t count, std::vector<double>* out) {
  const T* typed = static_cast<const T*>(data);
  for (std::size_t i = 0; i < count; ++i) out->push_back(static_cast<double>(typed[i]));
}

const char* ClassName(matio_classes c) {
  switch (c) {
    case MAT_C_CELL:
      return "cell";
    case MAT_C_STRUCT:
      return "struct";
    case MAT_C_OBJECT:
      return "object";
    case MAT_C_CHAR:
      return "char";
    case MAT_C_SPARSE:
      return "sparse";
    case MAT_C_FUNCTION:
      return "function";
    case MAT_C_OPAQUE:
      return "opaque";
    default:
      return "numeric";
  }
}

// Bytes per element of a real numeric class; 0 for anything that is not a numeric matrix.
std::size_t NumericElementSize(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE:
      return sizeof(double);
    case MAT_C_SINGLE:
      return sizeof(float);
    case MAT_C_INT8:
    case MAT_C_UINT8:
      return 1;
    case MAT_C_INT16:
    case MAT_C_UINT16:
      return 2;
    case MAT_C_INT32:
    case MAT_C_UINT32:
      return 4;
    case MAT_C_INT64:
    case MAT_C_UINT64:
      return 8;
    default:
      return 0;
  }
}

Result<NumericMatrix> ReadNumericMatrix(const matvar_t* var, const std::string& where) {
  if (var->rank != 2) {
    return Status::InvalidArgument(where + " has " + std::to_string(var->rank) +
                                   " dimensions, expected a 2-D matrix");
  }
  if (var->isComplex) return Status::InvalidArgument(where + " is complex, expected real numbers");
  NumericMatrix m;
  m.rows = var->dims[0];
  m.cols = var->dims[1];
  const std::size_t count = m.rows * m.cols;
  if (count == 0) return m;
  if (var->data == nullptr) return Status::DataLoss(where + " holds no data");
  const std::size_t element_size = NumericElementSize(var->class_type);
  if (element_size == 0) {
    return Status::InvalidArgument(where + " is a " + ClassName(var->class_type) +
                                   " array, expected a numeric matrix");
  }
  // Mat_VarRead converts the stored element type to the variable's class, so data_size must
  // match the class's C type; checking it guards against reading past the buffer.
  if (static_cast<std::size_t>(var->data_size) != element_size ||
      var->nbytes < count * element_size) {
    return Status::DataLoss(where + " has an inconsistent element size");
  }
  m.values.reserve(count);
  switch (var->class_type) {
    case MAT_C_DOUBLE:
      AppendAs<double>(var->data, count, &m.values);
      break;
    case MAT_C_SINGLE:
      AppendAs<float>(var->data, count, &m.values);
      break;
    case MAT_C_INT8:
      AppendAs<std::int8_t>(var->data, count, &m.values);
      break;
    case MAT_C_UINT8:
      AppendAs<std::uint8_t>(var->data, count, &m.values);
      break;
    case MAT_C_INT16:
      AppendAs<std::int16_t>(var->data, count, &m.values);
      break;
    case MAT_C_UINT16:
      AppendAs<std::uint16_t>(var->data, count, &m.values);
      break;
    case MAT_C_INT32:
      AppendAs<std::int32_t>(var->data, count, &m.values);
      break;
    case MAT_C_UINT32:
      AppendAs<std::uint32_t>(var->data, count, &m.values);
      break;
    case MAT_C_INT64:
      AppendAs<std::int64_t>(var->data, count, &m.values);
      break;
    default:
      AppendAs<std::uint64_t>(var->data, count, &m.values);
      break;  // MAT_C_UINT64
  }
  return m;
}

// Field lookup by name over the struct's own field list (Mat_VarGetStructFieldByName logs to
// stderr when a field is missing; a missing field is reported through our Status instead).
const matvar_t* FindField(matvar_t* structure, const char* field) {
  const unsigned n = Mat_VarGetNumberOfFields(structure);
  char* const* names = Mat_VarGetStructFieldnames(structure);
  if (names == nullptr) return nullptr;
  for (unsigned i = 0; i < n; ++i) {
    if (names[i] != nullptr && std::strcmp(names[i], field) == 0) {
      return Mat_VarGetStructFieldByIndex(structure, i, 0);
    }
  }
  return nullptr;
}

std::size_t ElementCount(const matvar_t& var) {
  std::size_t count = var.rank > 0 ? 1 : 0;
  for (int i = 0; i < var.rank; ++i) count *= var.dims[i];
  return count;
}

std::string Shape(const NumericMatrix& m) {
  return std::to_string(m.rows) + "x" + std::to_string(m.cols);
}

}  // namespace

namespace {

// libmatio allocates whatever sizes the file claims: the file's size and its declared sizes are
// checked before it sees the file (mat5_bounds.h).
Status CheckBeforeMatio(const std::string& mat_path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(mat_path, ec)) {
    return Status::NotFound(mat_path + ": annotation file not found");
  }
  const auto bytes = std::filesystem::file_size(mat_path, ec);
  if (ec) return Status::NotFound(mat_path + ": cannot read the annotation file");
  if (bytes > kMaxMatFileBytes) {
    return Status::DataLoss(mat_path + ": " + std::to_string(bytes) +
                            " bytes is too large for an annotation file");
  }
  std::ifstream in(mat_path, std::ios::binary);
  const std::string contents((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  return CheckMat5Bounds(contents, mat_path);
}

// Nx2 [x y] points. Empty arrays of any shape (0x0, 0x2) mean "no points".
Result<std::vector<cv::Point2d>> SeaEdgePoints(const NumericMatrix& m, const std::string& where) {
  std::vector<cv::Point2d> points;
  if (m.values.empty()) return points;
  if (m.cols != 2) {
    return Status::InvalidArgument(where + " is " + Shape(m) + ", expected Nx2 [x y] points");
  }
  for (std::size_t r = 0; r < m.rows; ++r) points.emplace_back(m.at(r, 0), m.at(r, 1));
  return points;
}

// Mx4 [x y w h] boxes. Empty arrays of any shape (0x0, 0x4) mean "no obstacles". The sea edge
// may hold NaN / Inf by design; a box may not (the official code would index with it and fail).
Result<std::vector<cv::Rect2d>> ObstacleBoxes(const NumericMatrix& m, const std::string& where) {
  std::vector<cv::Rect2d> boxes;
  if (m.values.empty()) return boxes;
  if (m.cols != 4) {
    return Status::InvalidArgument(where + " is " + Shape(m) + ", expected Mx4 [x y w h] boxes");
  }
  for (std::size_t r = 0; r < m.rows; ++r) {
    const cv::Rect2d box(m.at(r, 0), m.at(r, 1), m.at(r, 2), m.at(r, 3));
    if (!std::isfinite(box.x) || !std::isfinite(box.y) || !std::isfinite(box.width) ||
        !std::isfinite(box.height)) {
      return Status::InvalidArgument(where + " row " + std::to_string(r + 1) +
                                     " holds a non-finite value");
    }
    boxes.push_back(box);
  }
  return boxes;
}

}  // namespace

Result<Modd2Annotation> ReadModd2Annotation(const std::string& mat_path) {
  if (Status checked = CheckBeforeMatio(mat_path); !checked.ok()) return checked;
  const MatFile mat(Mat_Open(mat_path.c_str(), MAT_ACC_RDONLY));
  if (!mat) return Status::DataLoss(mat_path + ": not a readable MAT file");
  const MatVar annotations(Mat_VarRead(mat.get(), "annotations"));
  if (!annotations) return Status::NotFound(mat_path + ": no variable 'annotations'");
  if (annotations->class_type != MAT_C_STRUCT) {
    return Status::InvalidArgument(mat_path + ": 'annotations' is a " +
                                   ClassName(annotations->class_type) + ", expected a struct");
  }
  if (ElementCount(*annotations) != 1) {
    return Status::InvalidArgument(mat_path + ": 'annotations' must be a 1x1 struct");
  }

  const std::string prefix = mat_path + ": field 'annotations.";
  const matvar_t* sea_edge_var = FindField(annotations.get(), "sea_edge");
  if (sea_edge_var == nullptr) return Status::NotFound(prefix + "sea_edge' missing");
  const matvar_t* obstacles_var = FindField(annotations.get(), "obstacles");
  if (obstacles_var == nullptr) return Status::NotFound(prefix + "obstacles' missing");
  Result<NumericMatrix> sea_edge = ReadNumericMatrix(sea_edge_var, prefix + "sea_edge'");
  if (!sea_edge.ok()) return sea_edge.status();
  Result<NumericMatrix> obstacles = ReadNumericMatrix(obstacles_var, prefix + "obstacles'");
  if (!obstacles.ok()) return obstacles.status();

  Modd2Annotation annotation;
  auto points = SeaEdgePoints(*sea_edge, prefix + "sea_edge'");
  if (!points.ok()) return points.status();
  annotation.sea_edge = std::move(*points);
  auto boxes = ObstacleBoxes(*obstacles, prefix + "obstacles'");
  if (!boxes.ok()) return boxes.status();
  annotation.obstacles = std::move(*boxes);
  return annotation;
}

}  // namespace tod
