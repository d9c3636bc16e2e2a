#include "tests/modd2/mat_fixture.h"

#include <memory>

namespace tod::modd2_test {
namespace {

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatVarPtr = std::unique_ptr<matvar_t, MatVarFreer>;

// A matio variable holding `m` (column-major, as MATLAB stores it); matio copies the data.
MatVarPtr CreateVariable(const MatMatrix& m, const char* name) {
  std::size_t dims[2] = {m.rows, m.cols};
  std::vector<double> doubles(m.rows * m.cols);
  std::vector<float> floats(m.rows * m.cols);
  for (std::size_t r = 0; r < m.rows; ++r) {
    for (std::size_t c = 0; c < m.cols; ++c) {
      doubles[r + c * m.rows] = m.row_major[r * m.cols + c];
      floats[r + c * m.rows] = static_cast<float>(m.row_major[r * m.cols + c]);
    }
  }
  void* data = nullptr;
  if (!doubles.empty()) data = m.single ? static_cast<void*>(floats.data()) : doubles.data();
  return MatVarPtr(Mat_VarCreate(name, m.single ? MAT_C_SINGLE : MAT_C_DOUBLE,
                                 m.single ? MAT_T_SINGLE : MAT_T_DOUBLE, 2, dims, data, 0));
}

}  // namespace

MatMatrix Matrix(std::string name, const std::vector<std::vector<double>>& rows, std::size_t cols,
                 bool single) {
  MatMatrix m;
  m.name = std::move(name);
  m.single = single;
  m.rows = rows.size();
  m.cols = rows.empty() ? cols : rows.front().size();
  for (const auto& row : rows) m.row_major.insert(m.row_major.end(), row.begin(), row.end());
  return m;
}

bool WriteStructMat(const std::string& path, const std::string& variable,
                    const std::vector<MatMatrix>& fields, matio_compression compression,
                    std::size_t elements) {
  std::unique_ptr<mat_t, MatFileCloser> mat(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5));
  if (!mat) return false;
  std::vector<const char*> names;
  for (const MatMatrix& f : fields) names.push_back(f.name.c_str());
  std::size_t dims[2] = {elements, 1};
  MatVarPtr structure(Mat_VarCreateStruct(variable.c_str(), 2, dims, names.data(),
                                          static_cast<unsigned>(names.size())));
  if (!structure) return false;
  for (const MatMatrix& f : fields) {
    MatVarPtr field = CreateVariable(f, nullptr);
    if (!field) return false;
    // The struct owns its fields from here on.
    Mat_VarSetStructFieldByName(structure.get(), f.name.c_str(), 0, field.release());
  }
  return Mat_VarWrite(mat.get(), structure.get(), compression) == 0;
}

bool WriteNumericMat(const std::string& path, const MatMatrix& variable,
                     matio_compression compression, mat_ft version) {
  std::unique_ptr<mat_t, MatFileCloser> mat(Mat_CreateVer(path.c_str(), nullptr, version));
  if (!mat) return false;
  MatVarPtr var = CreateVariable(variable, variable.name.c_str());
  return var && Mat_VarWrite(mat.get(), var.get(), compression) == 0;
}

bool WriteAnnotation(const std::string& path, const std::vector<std::vector<double>>& sea_edge,
                     const std::vector<std::vector<double>>& obstacles,
                     matio_compression compression, bool single) {
  return WriteStructMat(
      path, "annotations",
      {Matrix("sea_edge", sea_edge, 2, single), Matrix("obstacles", obstacles, 4, single)},
      compression);
}

}  // namespace tod::modd2_test
