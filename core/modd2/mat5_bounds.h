// A bounds check of a Level-5 MAT file before libmatio reads it. libmatio (1.5.23, Debian 12)
// trusts the dimensions in the file: a 378-byte file whose struct claims 10^9 elements makes
// Mat_VarRead allocate one matvar_t per claimed field, gigabytes before it notices the data is
// missing (found by fuzz_modd2_mat, README "Fuzzing"). This walks the file's matrix headers
// (inflating compressed variables, up to a cap) and refuses any array that claims more elements
// than its own bytes could hold.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod {

// Largest file and largest inflated variable accepted (MODDv2 annotations are a few hundred bytes).
inline constexpr size_t kMaxMatFileBytes = 64u << 20;

// Ok when every array in `bytes` (a whole MAT file) is consistent with its size, or when the file
// is not a Level-5 MAT file (libmatio then reports what it is). DataLoss naming `what` otherwise.
Status CheckMat5Bounds(std::string_view bytes, const std::string& what);

}  // namespace tod
