// Results that must survive are written to a temporary name in the same directory and renamed,
// so a reader never sees a half-written file and a crash leaves the old file intact.
#pragma once

#include <string>

#include "core/base/status.h"

namespace tod {

Status WriteFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace tod
