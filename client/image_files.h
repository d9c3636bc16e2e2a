// Image inputs of the command-line tools: files and folders of .png/.jpg/.jpeg.
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod::client {

// Each argument is an image file or a folder (its images, not recursive, sorted by name).
// Errors name the path that does not exist or holds no image.
Result<std::vector<std::string>> CollectImages(const std::vector<std::string>& paths);

Result<std::string> ReadFileBytes(const std::string& path);
Status WriteFileBytes(const std::string& path, const std::string& bytes);

// "image/png" or "image/jpeg" from the file extension (case-insensitive); png when unknown.
std::string ContentTypeFor(const std::string& path);

}  // namespace tod::client
