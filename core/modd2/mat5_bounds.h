// A bounds check of a MAT file before libmatio reads it. libmatio (1.5.23, Debian 12) trusts the
// sizes in the file (both found by fuzz_modd2_mat, docs/service.md#found-and-fixed):
//  - a 378-byte file whose struct claims 10^9 elements makes Mat_VarRead allocate one matvar_t per
//    claimed field, gigabytes before it notices the data is missing;
//  - a file without a Level-5 header is read as MAT v4, whose 20-byte header gives a name length
//    that Mat_Open allocates (and clears) before reading: 147 bytes claiming a 1.1 GB name took
//    over 25 s per open under the fuzzer's sanitizers.
// So this accepts only Level-5 files (and the header of a v7.3/HDF5 file), walks their matrix
// headers as libmatio reads them (inflating compressed variables, up to a cap; the dimensions of
// every class; function handles as cells) and refuses any array that claims more elements than
// its own bytes could hold.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod {

// Largest file and largest inflated variable accepted (MODDv2 annotations are a few hundred bytes).
inline constexpr size_t kMaxMatFileBytes = 64u << 20;

// Ok when `bytes` (a whole MAT file) is a Level-5 file whose every array is consistent with its
// size, or a v7.3 file (left to libmatio). DataLoss naming `what` otherwise, including for MAT v4
// files and anything without a MAT header.
Status CheckMat5Bounds(std::string_view bytes, const std::string& what);

}  // namespace tod
