// The checksum model files and the bundle manifest carry: enough to detect a truncated or altered
// file, cheap to compute, and fixed by the file formats (changing it changes every stored model).
#pragma once

#include <cstdint>
#include <string_view>

namespace tod {

inline constexpr std::uint64_t kFnv1a64OffsetBasis = 0xCBF29CE484222325ULL;

// 64-bit FNV-1a of `bytes`, starting from `basis` (the standard offset basis unless a format
// fixed another one).
std::uint64_t Fnv1a64(std::string_view bytes, std::uint64_t basis = kFnv1a64OffsetBasis);

}  // namespace tod
