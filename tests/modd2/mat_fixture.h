// Test-only writer of MAT files in the MODDv2 annotation layout, with the knobs the reader must
// cope with: compression, double or single class, empty arrays of any shape, extra or missing
// fields, wrong shapes and non-struct variables. Uses libmatio's write API.
#pragma once

#include <matio.h>

#include <string>
#include <vector>

namespace tod::modd2_test {

struct MatMatrix {
  std::string name;  // field or variable name
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<double> row_major;  // rows * cols values, row by row
  bool single = false;            // store as MAT_C_SINGLE instead of MAT_C_DOUBLE
};

// A matrix from rows of values; `cols` gives the width of an empty matrix (0x0 or 0x4).
MatMatrix Matrix(std::string name, const std::vector<std::vector<double>>& rows,
                 std::size_t cols = 0, bool single = false);

// Writes `variable` as a struct array of `elements` x 1 (element 0 holds the fields, others stay
// empty) to a Level-5 file. Returns false when matio fails.
bool WriteStructMat(const std::string& path, const std::string& variable,
                    const std::vector<MatMatrix>& fields,
                    matio_compression compression = MAT_COMPRESSION_ZLIB, std::size_t elements = 1);

// Writes one numeric variable (e.g. a non-struct 'annotations'), to a Level-5 file by default.
bool WriteNumericMat(const std::string& path, const MatMatrix& variable,
                     matio_compression compression = MAT_COMPRESSION_NONE,
                     mat_ft version = MAT_FT_MAT5);

// The usual annotation file: struct 'annotations' with sea_edge (Nx2) and obstacles (Mx4).
bool WriteAnnotation(const std::string& path, const std::vector<std::vector<double>>& sea_edge,
                     const std::vector<std::vector<double>>& obstacles,
                     matio_compression compression = MAT_COMPRESSION_ZLIB, bool single = false);

}  // namespace tod::modd2_test
